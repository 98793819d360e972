// SPDX-License-Identifier: MIT
// hrg-board: the firmware on the Linux board target in real time, with the
// simulated converters of sim_target behind the ADC/DAC seam (no hardware
// needed) and real SocketCAN, libgpiod lines and CLOCK_MONOTONIC.
//   hrg-board --can IF [--gpio-chip CHIP --exc-line N --fault-line N] [--seconds S]
//             [--calibration FILE] [--cal-secret HEX] [--lockstep]
// The firmware sends its telemetry on IF at the default rates, answers the
// commands of the DBC and restarts the controller after 100 ms of bus-off, all
// through its own CAN link (receive filter set at start). Runs until
// SIGTERM/SIGINT or S seconds. --calibration FILE (hrg audit --calibration)
// puts that calibration in force from the start; --cal-secret HEX (32 hex
// digits) is the gyro's secret for the guarded write over CAN
// (hrg can-calibrate), all zero when not given. As the bench behind the
// simulated converters, it puts the simulated input rate and temperature on
// the bus (LAB_TABLE, one per recording row), so a candump of IF decodes into
// an audit-grade recording (hrg can-decode). --lockstep paces the firmware by
// the simulated converters instead of CLOCK_MONOTONIC (an emulator or a slow
// machine: nothing is missed, the bus carries the same frames sooner; the
// recording's time is the firmware's, HRG_ROW.t_s).
#include <signal.h>

#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <numbers>
#include <string>

#include "can/calibration_sender.hpp"
#include "firmware/app/firmware.hpp"
#include "firmware/calibration_file.hpp"
#include "hal/linux/gpiod_line.hpp"
#include "hal/linux/linux_clock.hpp"
#include "hal/linux/realtime.hpp"
#include "hal/linux/socket_can.hpp"
#include "sim_target/control.hpp"
#include "sim_tools/job.hpp"

using namespace hrg;
namespace lb = hrg::hal::linux_board;

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_stop(int) { g_stop = 1; }

struct Options {
  std::string can = "can0";
  std::string gpio_chip;  // empty: the simulated lines
  unsigned exc_line = 0;
  unsigned fault_line = 1;
  double seconds = 1e9;
  std::string calibration;  // empty: the identity
  fw::can::CalSecret cal_secret{};
  bool lockstep = false;
};

int usage() {
  std::fprintf(stderr,
               "usage: hrg-board --can IF [--gpio-chip CHIP --exc-line N --fault-line N] "
               "[--seconds S] [--calibration FILE] [--cal-secret HEX] [--lockstep]\n");
  return 2;
}

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--lockstep") {
      o.lockstep = true;
      continue;
    }
    if (i + 1 >= argc) return false;
    const char* v = argv[++i];
    if (a == "--can") {
      o.can = v;
    } else if (a == "--gpio-chip") {
      o.gpio_chip = v;
    } else if (a == "--exc-line") {
      o.exc_line = static_cast<unsigned>(std::atoi(v));
    } else if (a == "--fault-line") {
      o.fault_line = static_cast<unsigned>(std::atoi(v));
    } else if (a == "--seconds") {
      o.seconds = std::atof(v);
    } else if (a == "--calibration") {
      o.calibration = v;
    } else if (a == "--cal-secret") {
      if (!can::parse_secret(v, o.cal_secret)) return false;
    } else {
      return false;
    }
  }
  return true;
}

// The bench behind the simulated converters: the input rate and temperature
// the firmware's next recording row will have seen (the centre of its
// demodulator window, kCentre blocks and a half back), sent as LAB_TABLE just
// before the firmware sends that row, so a reader pairs each row with the
// latest LAB_TABLE before it.
class LabTable {
 public:
  explicit LabTable(const sim::SimTarget& sim) {
    for (auto& s : hist_)
      s = sim.true_state();
    period_ =
        fw::kBaseRateHz /
        fw::can::TelemetryConfig::defaults().rate_hz[static_cast<std::size_t>(fw::can::Tm::row)];
  }
  void before_frame(uint64_t k, hal::CanBus& can) {
    if (k < hist_.size() || k % period_ != 0) return;
    // After block k - 1, the window of frame k's row is centred between the
    // ends of blocks k - 3 and k - 2.
    const double rate_dps =
        0.5 * (hist_[1].rate_rad_s + hist_[2].rate_rad_s) * 180.0 / std::numbers::pi;
    const double temp_c = 0.5 * (hist_[1].temp_c + hist_[2].temp_c);
    (void)can.send(fw::can::encode_lab_table(rate_dps, temp_c, seq_++));
  }
  void after_frame(const sim::SimTarget& sim) {
    for (std::size_t i = hist_.size() - 1; i > 0; --i)
      hist_[i] = hist_[i - 1];
    hist_[0] = sim.true_state();
  }

 private:
  std::array<sim::TrueState, 4> hist_{};
  uint64_t period_ = 10;
  uint8_t seq_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) return usage();

  simtools::JobConfig job = simtools::default_job(o.seconds > 3600 ? 3600 : o.seconds, 0);
  job.firmware.gyro.calibration_service.secret = o.cal_secret;
  if (!o.calibration.empty()) {
    try {
      job.firmware.calibration = fw::load_calibration(o.calibration).calibration;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "hrg-board: %s\n", e.what());
      return 2;
    }
  }
  sim::SimTarget& sim = sim::target();
  sim.configure(job.sim);
  hal::Board& sim_board = sim.board();

  lb::SocketCan can;
  if (const hal::Status s = can.open(o.can.c_str()); s != hal::Status::ok) {
    std::fprintf(stderr, "hrg-board: cannot open CAN interface %s: %s\n", o.can.c_str(),
                 hal::to_string(s));
    return 1;
  }
  lb::GpiodOutput exc_line;
  lb::GpiodInput fault_line;
  hal::DigitalOut* exc = &sim_board.excitation_enable;
  hal::DigitalIn* fault = &sim_board.fault_input;
  if (!o.gpio_chip.empty()) {
    lb::LineConfig lc;
    lc.chip = o.gpio_chip.c_str();
    lc.offset = o.exc_line;
    const hal::Status se = exc_line.open(lc);
    lc.offset = o.fault_line;
    const hal::Status sf = fault_line.open(lc);
    if (se != hal::Status::ok || sf != hal::Status::ok) {
      std::fprintf(stderr, "hrg-board: GPIO lines %u/%u on %s: %s/%s\n", o.exc_line, o.fault_line,
                   lc.chip, hal::to_string(se), hal::to_string(sf));
      return 1;
    }
    exc = &exc_line;
    fault = &fault_line;
  }
  lb::LinuxClock clock;
  // In lockstep the simulated converters' clock paces, the host's times the tasks.
  hal::Board board{sim_board.adc, sim_board.dac, *exc,
                   *fault,        can,           o.lockstep ? sim_board.clock : clock};

  if (!o.lockstep) {
    char rt[200];
    std::printf("hrg-board: %s\n", lb::describe(lb::setup_realtime({}), rt, sizeof rt));
  }
  // Large (the chain holds its filters): allocated once, before the loop.
  auto firmware = std::make_unique<fw::app::Firmware>(
      board, clock, o.lockstep ? fw::Pacing::lockstep : fw::Pacing::real_time, job.firmware);
  if (const char* err = firmware->error()) {
    std::fprintf(stderr, "hrg-board: %s\n", err);
    return 1;
  }
  fw::Gyro* gyro = &firmware->gyro();
  struct sigaction sa {};
  sa.sa_handler = on_stop;
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  const auto frames = static_cast<uint64_t>(std::llround(o.seconds * fw::kBaseRateHz));
  uint64_t k = 0;
  int exc_edges = 0;
  bool last_exc = false;
  LabTable lab(sim);
  for (; k < frames && g_stop == 0; ++k) {
    lab.before_frame(k, can);
    gyro->run_frame();
    lab.after_frame(sim);
    const fw::GyroStatus& st = gyro->status();
    if (st.enable_line != last_exc) ++exc_edges;
    last_exc = st.enable_line;
  }
  const auto& fs = gyro->executive().frame_stats();
  const auto c = can.counters();
  std::printf(
      "hrg-board: %.3f s on %s: %llu frames, %u deadline misses, %u missed frames, max frame "
      "%.3f ms; mode %d, faults 0x%04x; excitation edges %d; commands %u accepted %u refused; "
      "CAN tx %u, refused %u, tx_queue_full %u, bus-off %u, restarts %u\n",
      static_cast<double>(k) / fw::kBaseRateHz, o.can.c_str(),
      static_cast<unsigned long long>(fs.frames), fs.deadline_misses, fs.missed_frames,
      fs.max_frame_ns * 1e-6, static_cast<int>(gyro->status().mode), gyro->status().faults,
      exc_edges, gyro->commands_accepted(), gyro->commands_refused(), c.tx_frames,
      gyro->can_tx_refused(), c.tx_queue_full, c.bus_off_events, c.restarts);
  return 0;
}
