// SPDX-License-Identifier: MIT
#include "hal/linux/board_linux.hpp"

#include <cstdlib>
#include <cstring>

#include "hal/linux/file_temperature.hpp"
#include "hal/linux/gpiod_line.hpp"
#include "hal/linux/linux_clock.hpp"
#include "hal/linux/socket_can.hpp"

namespace hrg::hal::linux_board {

namespace {

const char* env_or(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? v : fallback;
}

unsigned env_unsigned(const char* name, unsigned fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  char* end = nullptr;
  const unsigned long n = std::strtoul(v, &end, 10);
  return *end == '\0' ? static_cast<unsigned>(n) : fallback;
}

double env_double(const char* name, double fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  char* end = nullptr;
  const double d = std::strtod(v, &end);
  return *end == '\0' && d > 0 ? d : fallback;
}

// Everything the board owns, built on the first board() call.
struct LinuxBoard {
  SocketCan can;
  GpiodOutput excitation;
  GpiodInput fault;
  StreamAdc adc;
  StreamDac dac;
  LinuxClock clock;
  FileTemperatureSensor temperature;
  BoardOpenStatus status;
  Board board{adc, dac, excitation, fault, can, clock, temperature};

  LinuxBoard() {
    status.can = can.open(env_or("HRG_CAN_IF", "can0"));
    LineConfig line;
    line.chip = env_or("HRG_GPIO_CHIP", "gpiochip0");
    line.offset = env_unsigned("HRG_EXC_LINE", 0);
    line.active_low = env_unsigned("HRG_EXC_ACTIVE_LOW", 0) != 0;
    status.excitation = excitation.open(line);
    // Drives stay off until the firmware's mode machine asks for them.
    if (status.excitation == Status::ok) excitation.write(false);
    line.offset = env_unsigned("HRG_FAULT_LINE", 1);
    line.active_low = false;
    status.fault = fault.open(line);
    const uint32_t rate = env_unsigned("HRG_SAMPLE_RATE_HZ", 100'000);
    const uint32_t frames = env_unsigned("HRG_BLOCK_FRAMES", 100);
    StreamConfig adc_cfg{{rate, frames, env_double("HRG_ADC_FULL_SCALE_V", 2.5)}, {}};
    StreamConfig dac_cfg{{rate, frames, env_double("HRG_DAC_FULL_SCALE_V", 10.0)}, {}};
    const bool formats_ok =
        parse_iio_type(env_or("HRG_ADC_FORMAT", "le:s16/16>>0"), adc_cfg.format) &&
        parse_iio_type(env_or("HRG_DAC_FORMAT", "le:s16/16>>0"), dac_cfg.format);
    if (formats_ok) {
      status.adc = adc.open(env_or("HRG_ADC_DEV", "/dev/iio:device0"), adc_cfg, clock);
      status.dac = dac.open(env_or("HRG_DAC_DEV", "/dev/iio:device1"), dac_cfg);
    } else {
      status.adc = status.dac = Status::invalid_argument;
    }
    if (const char* temp_path = env_or("HRG_TEMP_PATH", nullptr)) {
      status.temperature = temperature.open(temp_path);
      status.temperature_error = temperature.error();
    }
  }
};

LinuxBoard& instance() {
  static LinuxBoard b;
  return b;
}

}  // namespace

BoardOpenStatus board_open_status() { return instance().status; }

}  // namespace hrg::hal::linux_board

namespace hrg::hal {

Board& board() { return linux_board::instance().board; }

}  // namespace hrg::hal
