// SPDX-License-Identifier: MIT
// hrg-board: the firmware (firmware/app) in real time on hrg::hal::board() of
// the Linux target (hrg_board_linux, chosen at link time): SocketCAN, libgpiod
// lines, CLOCK_MONOTONIC and, with --converters board, the IIO sample streams.
// By default the simulated converters of sim_target stand behind the ADC/DAC
// seam instead (no converter hardware needed).
//   hrg-board --can IF [--gpio-chip CHIP --exc-line N --fault-line N] [--seconds S]
//             [--calibration FILE] [--converters sim|board] [--cal-secret HEX] [--lockstep]
//             [--temp-path FILE]
// The options set the board's environment (HRG_CAN_IF, HRG_GPIO_CHIP,
// HRG_EXC_LINE, HRG_FAULT_LINE; the rest as hal/linux/board_linux.hpp says).
// Without a GPIO chip (option or HRG_GPIO_CHIP) the simulated lines are used.
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
// recording's time is the firmware's, HRG_ROW.t_s). --temp-path FILE
// (HRG_TEMP_PATH) is the resonator's temperature sensor, a file of
// millidegrees C (IIO in_temp*_input, hwmon temp*_input); a file that does
// not read as one stops the program naming it. Without it the simulated
// converters bring the simulated sensor, board converters none.
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
#include "hal/board.hpp"
#include "hal/linux/board_linux.hpp"
#include "hal/linux/realtime.hpp"
#include "sim_target/control.hpp"
#include "sim_run/run.hpp"

using namespace hrg;
namespace lb = hrg::hal::linux_board;

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_stop(int) { g_stop = 1; }

struct Options {
  double seconds = 1e9;
  std::string calibration;        // empty: the identity
  bool board_converters = false;  // false: the simulated converters
  fw::can::CalSecret cal_secret{};
  bool lockstep = false;
};

int usage() {
  std::fprintf(stderr,
               "usage: hrg-board --can IF [--gpio-chip CHIP --exc-line N --fault-line N] "
               "[--seconds S] [--calibration FILE] [--converters sim|board] [--cal-secret HEX] "
               "[--lockstep] [--temp-path FILE]\n");
  return 2;
}

// The board's devices are named in its environment (board_linux.hpp); the
// options set it before the first hal::board() call opens them.
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
      setenv("HRG_CAN_IF", v, 1);
    } else if (a == "--gpio-chip") {
      setenv("HRG_GPIO_CHIP", v, 1);
    } else if (a == "--exc-line") {
      setenv("HRG_EXC_LINE", v, 1);
    } else if (a == "--fault-line") {
      setenv("HRG_FAULT_LINE", v, 1);
    } else if (a == "--temp-path") {
      setenv("HRG_TEMP_PATH", v, 1);
    } else if (a == "--seconds") {
      o.seconds = std::atof(v);
    } else if (a == "--calibration") {
      o.calibration = v;
    } else if (a == "--cal-secret") {
      if (!can::parse_secret(v, o.cal_secret)) return false;
    } else if (a == "--converters" &&
               (std::strcmp(v, "sim") == 0 || std::strcmp(v, "board") == 0)) {
      o.board_converters = std::strcmp(v, "board") == 0;
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

const char* env_or(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? v : fallback;
}

// The board of the firmware: CAN and clock of the Linux board; its lines when
// a GPIO chip is named, else the simulation's; its converters or the
// simulation's; in lockstep the simulated converters' clock paces. nullptr (after saying why) when
// a device asked for is closed.
std::unique_ptr<hal::Board> assemble_board(const Options& o, hal::Board& sim) {
  hal::Board& hw = hal::board();
  const lb::BoardOpenStatus st = lb::board_open_status();
  if (st.can != hal::Status::ok) {
    std::fprintf(stderr, "hrg-board: cannot open CAN interface %s: %s\n",
                 env_or("HRG_CAN_IF", "can0"), hal::to_string(st.can));
    return nullptr;
  }
  const bool board_lines = std::getenv("HRG_GPIO_CHIP") != nullptr;
  if (board_lines && (st.excitation != hal::Status::ok || st.fault != hal::Status::ok)) {
    std::fprintf(stderr, "hrg-board: GPIO lines %s/%s on %s: %s/%s\n", env_or("HRG_EXC_LINE", "0"),
                 env_or("HRG_FAULT_LINE", "1"), env_or("HRG_GPIO_CHIP", ""),
                 hal::to_string(st.excitation), hal::to_string(st.fault));
    return nullptr;
  }
  if (o.board_converters && (st.adc != hal::Status::ok || st.dac != hal::Status::ok)) {
    std::fprintf(
        stderr, "hrg-board: converters %s/%s: %s/%s\n", env_or("HRG_ADC_DEV", "/dev/iio:device0"),
        env_or("HRG_DAC_DEV", "/dev/iio:device1"), hal::to_string(st.adc), hal::to_string(st.dac));
    return nullptr;
  }
  const bool board_temp = std::getenv("HRG_TEMP_PATH") != nullptr;
  if (board_temp && st.temperature != hal::Status::ok) {
    std::fprintf(stderr, "hrg-board: %s\n", st.temperature_error);
    return nullptr;
  }
  const hal::Board& conv = o.board_converters ? hw : sim;
  const hal::Board& lines = board_lines ? hw : sim;
  const hal::Board& temp = board_temp || o.board_converters ? hw : sim;
  return std::make_unique<hal::Board>(
      hal::Board{conv.adc, conv.dac, lines.excitation_enable, lines.fault_input, hw.can,
                 o.lockstep ? sim.clock : hw.clock, temp.temperature});
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) return usage();

  sim_run::RunConfig job = sim_run::default_run(o.seconds > 3600 ? 3600 : o.seconds, 0);
  job.firmware.gyro.calibration_service.secret = o.cal_secret;
  if (!o.calibration.empty()) {
    try {
      const fw::CalibrationFile f = fw::load_calibration(o.calibration);
      job.firmware.calibration = f.calibration;
      job.firmware.calibration_gap_sigma = fw::gap_sigma(f);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "hrg-board: %s\n", e.what());
      return 2;
    }
  }
  // The simulation's converters and lines (unused when the board's serve).
  auto sim = std::make_unique<sim::SimTarget>();
  sim->configure(job.sim);
  const std::unique_ptr<hal::Board> board = assemble_board(o, sim->board());
  if (!board) return 1;

  if (!o.lockstep) {
    char rt[200];
    std::printf("hrg-board: %s\n", lb::describe(lb::setup_realtime({}), rt, sizeof rt));
  }
  // Large (the chain holds its filters): allocated once, before the loop. The
  // host's clock times the tasks, in lockstep too.
  auto firmware = std::make_unique<fw::app::Firmware>(
      *board, hal::board().clock, o.lockstep ? fw::Pacing::lockstep : fw::Pacing::real_time,
      job.firmware);
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
  LabTable lab(*sim);
  for (; k < frames && g_stop == 0; ++k) {
    lab.before_frame(k, board->can);
    gyro->run_frame();
    lab.after_frame(*sim);
    const fw::GyroStatus& st = gyro->status();
    if (st.enable_line != last_exc) ++exc_edges;
    last_exc = st.enable_line;
  }
  const auto& fs = gyro->executive().frame_stats();
  const auto c = board->can.counters();
  std::printf(
      "hrg-board: %.3f s on %s: %llu frames, %u deadline misses, %u missed frames, max frame "
      "%.3f ms; mode %d, faults 0x%04x; excitation edges %d; commands %u accepted %u refused; "
      "CAN tx %u, refused %u, tx_queue_full %u, bus-off %u, restarts %u\n",
      static_cast<double>(k) / fw::kBaseRateHz, env_or("HRG_CAN_IF", "can0"),
      static_cast<unsigned long long>(fs.frames), fs.deadline_misses, fs.missed_frames,
      fs.max_frame_ns * 1e-6, static_cast<int>(gyro->status().mode), gyro->status().faults,
      exc_edges, gyro->commands_accepted(), gyro->commands_refused(), c.tx_frames,
      gyro->can_tx_refused(), c.tx_queue_full, c.bus_off_events, c.restarts);
  return 0;
}
