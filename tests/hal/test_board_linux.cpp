// SPDX-License-Identifier: MIT
// hrg::hal::board() of the Linux target (hrg_board_linux chosen at link time):
// devices come from the environment, a device that does not open is closed
// (never a crash), and the converter streams carry blocks in the configured
// IIO format. Named pipes stand in for the IIO devices.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "hal/board.hpp"
#include "hal/linux/board_linux.hpp"

#include "support/cpputest.hpp"

using namespace hrg::hal;
using namespace hrg::hal::linux_board;

namespace {

// Built before main (and before CppUTest's leak checking): the board is opened
// once per process on its first use.
struct Fixture {
  std::string adc_path;
  std::string dac_path;
  std::string temp_path;
  int adc_writer = -1;
  int dac_reader = -1;
  Fixture() {
    const std::string base = "/tmp/hrg-board-test-" + std::to_string(::getpid());
    adc_path = base + "-adc";
    dac_path = base + "-dac";
    temp_path = base + "-temp1_input";
    const int temp_fd = ::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    (void)::write(temp_fd, "31250\n", 6);
    ::close(temp_fd);
    ::mkfifo(adc_path.c_str(), 0600);
    ::mkfifo(dac_path.c_str(), 0600);
    dac_reader = ::open(dac_path.c_str(), O_RDONLY | O_NONBLOCK);  // so the DAC can open
    ::setenv("HRG_CAN_IF", "hrgnone0", 1);
    ::setenv("HRG_GPIO_CHIP", "/nonexistent/gpiochip", 1);
    ::setenv("HRG_ADC_DEV", adc_path.c_str(), 1);
    ::setenv("HRG_DAC_DEV", dac_path.c_str(), 1);
    ::setenv("HRG_ADC_FORMAT", "be:u12/16>>4", 1);
    ::setenv("HRG_DAC_FORMAT", "le:s16/16>>0", 1);
    ::setenv("HRG_BLOCK_FRAMES", "4", 1);
    ::setenv("HRG_ADC_FULL_SCALE_V", "3.3", 1);
    ::setenv("HRG_TEMP_PATH", temp_path.c_str(), 1);
    (void)board();
    adc_writer = ::open(adc_path.c_str(), O_WRONLY | O_NONBLOCK);
  }
  ~Fixture() {
    ::close(adc_writer);
    ::close(dac_reader);
    ::unlink(adc_path.c_str());
    ::unlink(dac_path.c_str());
    ::unlink(temp_path.c_str());
  }
};
Fixture fixture;

}  // namespace

TEST_GROUP(LinuxBoard){};

TEST(LinuxBoard, DevicesThatDoNotOpenAreClosedAndSaySo) {
  const BoardOpenStatus s = board_open_status();
  CHECK(is_fatal(s.can));
  CHECK(Status::invalid_argument == s.excitation);
  CHECK(Status::invalid_argument == s.fault);
  CHECK(Status::ok == s.adc);
  CHECK(Status::ok == s.dac);
  CanFrame f;
  CHECK(Status::closed == board().can.send(f));
  CHECK(Status::closed == board().excitation_enable.write(true));
  bool v = false;
  CHECK(Status::closed == board().fault_input.read(v));
}

TEST(LinuxBoard, TheTemperatureComesFromTheFileNamedByHrgTempPath) {
  const BoardOpenStatus s = board_open_status();
  CHECK(Status::ok == s.temperature);
  STRCMP_EQUAL("", s.temperature_error);
  double t = 0.0;
  CHECK(Status::ok == board().temperature.read(t));
  DOUBLES_EQUAL(31.25, t, 1e-12);
}

TEST(LinuxBoard, TheAdcStreamIsReadInItsIioFormat) {
  const ConverterInfo info = board().adc.info();
  LONGS_EQUAL(100'000, info.sample_rate_hz);
  LONGS_EQUAL(4, info.block_frames);
  DOUBLES_EQUAL(3.3, info.full_scale_v, 0);
  // be:u12/16>>4, offset binary: 0x800 is 0 V, 0xFFF the top code.
  const uint8_t bytes[16] = {0x80, 0x00, 0xFF, 0xF0, 0x00, 0x00, 0x80, 0x10,
                             0x80, 0x00, 0x80, 0x00, 0x80, 0x00, 0x7F, 0xF0};
  CHECK(::write(fixture.adc_writer, bytes, sizeof bytes) == 16);
  std::array<q31_t, 8> block{};
  uint64_t t = 0;
  uint32_t clipped = 0;
  CHECK(Status::ok == board().adc.read_block(block, t, clipped));
  LONGS_EQUAL(0, block[0]);
  LONGS_EQUAL(0x7FF00000, block[1]);
  LONGS_EQUAL(INT32_MIN, block[2]);
  LONGS_EQUAL(0x00100000, block[3]);
  LONGS_EQUAL(-0x00100000, block[7]);
  LONGS_EQUAL(2, clipped);
  CHECK(t > 0);
}

TEST(LinuxBoard, TheDacStreamIsWrittenInItsIioFormat) {
  std::array<q31_t, 12> block{};
  block[0] = 0x12345678;
  block[11] = INT32_MIN;
  CHECK(Status::ok == board().dac.write_block(block));
  uint8_t out[24] = {};
  CHECK(::read(fixture.dac_reader, out, sizeof out) == 24);
  LONGS_EQUAL(0x34, out[0]);  // le:s16: the top 16 bits, low byte first
  LONGS_EQUAL(0x12, out[1]);
  LONGS_EQUAL(0x00, out[22]);
  LONGS_EQUAL(0x80, out[23]);
}

TEST(LinuxBoard, IioScanElementTypesAreParsed) {
  SampleFormat f;
  CHECK(parse_iio_type("le:s16/16>>0", f));
  CHECK(f.is_signed && !f.big_endian && f.bits == 16 && f.storage_bytes == 2 && f.shift == 0);
  CHECK(parse_iio_type("be:u24/32>>8", f));
  CHECK(!f.is_signed && f.big_endian && f.bits == 24 && f.storage_bytes == 4 && f.shift == 8);
  const char* bad[] = {"",
                       "le:s16/16",
                       "xe:s16/16>>0",
                       "le:q16/16>>0",
                       "le:s16/12>>0",
                       "le:s16/16>>4",
                       "le:s12/16X2>>4",
                       "le:s16/16>>0 "};
  for (const char* b : bad)
    CHECK_FALSE_TEXT(parse_iio_type(b, f), b);
}
