// SPDX-License-Identifier: MIT
// Board rig for the kernel VM test: the Linux HAL (SocketCAN, libgpiod,
// CLOCK_MONOTONIC) driven at the 1 kHz base rate with the CAN protocol of
// firmware/can, a minimal mode logic and the identification window schedule
// switching the excitation enable line on a gpio-sim chip.
//   can_rig frames              shell assignments CMD_<NAME>=<cansend frame>
//   can_rig run IFACE SECONDS   run the board loop until SIGTERM or SECONDS; prints a
//                               summary, exit 1 on failure
//   can_rig check LOG           check a candump -L log of a scripted run
//   can_rig write-log FILE      a log for canplayer (CandumpLogWriter)
//   can_rig check-replay LOG    the replayed frames equal what write-log wrote
//   can_rig check-firmware LOG  check a capture of hrg-board (the firmware)
// Environment for run: HRG_GPIO_CHIP, HRG_GPIO_SYSFS (as test_hal_linux_kernel).
#include <signal.h>

#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "can/candump_log.hpp"
#include "firmware/can/command.hpp"
#include "firmware/can/link.hpp"
#include "firmware/can/telemetry.hpp"
#include "hal/linux/gpiod_line.hpp"
#include "hal/linux/linux_clock.hpp"
#include "hal/linux/realtime.hpp"
#include "hal/linux/socket_can.hpp"
#include "rig_script.hpp"

using namespace hrg;
using namespace hrg::fw::can;
using hal::CanFrame;
using hal::Status;

namespace {

constexpr uint32_t kBaseHz = fw::kBaseRateHz;
constexpr uint64_t kPeriodNs = 1'000'000'000ull / kBaseHz;

volatile std::sig_atomic_t g_stop = 0;
void on_stop(int) { g_stop = 1; }

std::string cansend_text(const CanFrame& f) {
  char buf[32];
  int n = std::snprintf(buf, sizeof buf, "%03X#", f.id);
  for (uint8_t i = 0; i < f.len; ++i)
    n += std::snprintf(buf + n, sizeof buf - n, "%02X", f.data[i]);
  return buf;
}

int cmd_frames() {
  for (const auto& step : rig::script()) {
    std::printf("CMD_%s=%s\n", step.name, cansend_text(step.frame).c_str());
  }
  return 0;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::string s;
  std::getline(in, s);
  return s;
}

struct RigState {
  fw::Mode mode = fw::Mode::operate;
  bool ident = false;
  uint64_t ident_start_frame = 0;
  double period_s = 10.0;
  double length_s = 1.0;
  double agc_v = 1.0;
  bool exc = true;
};

void apply(const Command& c, RigState& st, uint64_t frame) {
  switch (c.id) {
    case Cmd::set_mode:
      st.mode = c.mode == fw::Mode::ring_up ? fw::Mode::operate : c.mode;
      if (st.mode == fw::Mode::safe) st.ident = false;
      break;
    case Cmd::ident:
      st.ident = c.ident_start;
      st.ident_start_frame = frame;
      if (!st.ident && st.mode == fw::Mode::free_decay) st.mode = fw::Mode::operate;
      break;
    case Cmd::window:
      st.period_s = c.window_period_s;
      st.length_s = c.window_length_s;
      break;
    case Cmd::agc: st.agc_v = c.agc_setpoint_v; break;
    case Cmd::status_request: break;
  }
}

int cmd_run(const char* iface, double seconds) {
  hal::linux_board::SocketCan can;
  if (can.open(iface) != Status::ok) {
    std::fprintf(stderr, "can_rig: cannot open %s\n", iface);
    return 1;
  }
  CanLink link(can, kBaseHz / 10);  // restart after 100 ms bus-off
  link.init();
  hal::linux_board::GpiodOutput exc_line;
  hal::linux_board::LineConfig lc;
  lc.chip = std::getenv("HRG_GPIO_CHIP") ? std::getenv("HRG_GPIO_CHIP") : "gpiochip0";
  lc.offset = 0;
  const bool have_gpio = exc_line.open(lc) == Status::ok;
  const std::string value_path =
      std::string(std::getenv("HRG_GPIO_SYSFS") ? std::getenv("HRG_GPIO_SYSFS") : "") +
      "/sim_gpio0/value";
  char rt[200];
  std::printf("rig: %s\n",
              hal::linux_board::describe(hal::linux_board::setup_realtime({}), rt, sizeof rt));

  hal::linux_board::LinuxClock clock;
  TelemetryEncoder enc(TelemetryConfig::defaults(), kBaseHz);
  RigState st;
  if (have_gpio) exc_line.write(true);
  TelemetrySnapshot snap;
  snap.pll_freq_hz = 5000.0;
  snap.angular_gain = 0.554;
  snap.temp_c = 25.0;
  int toggles = 0, readback_errors = 0, missed = 0;
  double max_toggle_late_ms = 0;
  const uint64_t frames = static_cast<uint64_t>(seconds * kBaseHz);
  const uint64_t t0 = clock.now_ns();
  struct sigaction sa {};
  sa.sa_handler = on_stop;
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  uint64_t k = 0;
  for (; k < frames && g_stop == 0; ++k) {
    if (clock.sleep_until_ns(t0 + k * kPeriodNs) == Status::timeout) ++missed;
    // Commands first: a command acts in the frame it arrives in.
    Command cmd;
    while (link.poll({st.mode, 0, false, st.ident, st.agc_v}, cmd)) {
      apply(cmd, st, k);
      if (cmd.id == Cmd::status_request) {
        CanFrame status;
        snap.mode = st.mode;
        enc.encode_now(Tm::status, snap, status);
        link.send({&status, 1});
      }
    }
    // Window schedule: free decay for length_s at the start of every period.
    if (st.ident) {
      const auto period_frames = static_cast<uint64_t>(std::llround(st.period_s * kBaseHz));
      const auto length_frames = static_cast<uint64_t>(std::llround(st.length_s * kBaseHz));
      const uint64_t phase = (k - st.ident_start_frame) % period_frames;
      st.mode = phase < length_frames ? fw::Mode::free_decay : fw::Mode::operate;
    }
    const bool exc = st.mode == fw::Mode::operate;
    if (exc != st.exc) {
      st.exc = exc;
      if (have_gpio) {
        exc_line.write(exc);
        ++toggles;
        if (read_file(value_path) != (exc ? "1" : "0")) ++readback_errors;
        const double late_ms = static_cast<double>(clock.now_ns() - (t0 + k * kPeriodNs)) * 1e-6;
        if (late_ms > max_toggle_late_ms) max_toggle_late_ms = late_ms;
      }
    }
    link.service();
    snap.cx_v = exc ? st.agc_v : st.agc_v * 0.999;
    snap.mode = st.mode;
    snap.exc_on = exc;
    snap.exc_line = exc;
    snap.ident_active = st.ident;
    snap.agc_setpoint_v = st.agc_v;
    snap.window_period_s = st.period_s;
    snap.window_length_s = st.length_s;
    snap.missed_ticks = static_cast<uint32_t>(missed);
    snap.can = can.counters();
    snap.can_state = can.state();
    std::array<CanFrame, kTelemetryCount> out;
    const std::size_t n = enc.tick(snap, out);
    for (std::size_t i = 0; i < n; ++i)
      can.send(out[i]);
  }
  const auto c = can.counters();
  std::printf(
      "rig: %s %.1f s: frames %llu, missed deadlines %d, commands accepted %u refused %u, "
      "excitation toggles %d (sysfs read-back errors %d, latest %.3f ms after its frame), "
      "CAN tx %u, tx_queue_full %u, error frames %u, bus-off %u, restarts %u, state %d\n",
      iface, static_cast<double>(k) / kBaseHz, static_cast<unsigned long long>(k), missed,
      link.stats().commands_accepted, link.stats().commands_refused, toggles, readback_errors,
      max_toggle_late_ms, c.tx_frames, c.tx_queue_full, c.error_frames, c.bus_off_events,
      c.restarts, static_cast<int>(can.state()));
  if (!have_gpio) std::printf("rig: no GPIO line (%s)\n", lc.chip);
  return readback_errors == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string cmd = argc > 1 ? argv[1] : "";
  try {
    if (cmd == "frames") return cmd_frames();
    if (cmd == "run" && argc == 4) return cmd_run(argv[2], std::atof(argv[3]));
    if (cmd == "check" && argc == 3) return rig::check_log(argv[2]);
    if (cmd == "write-log" && argc == 3) return rig::write_replay_log(argv[2]);
    if (cmd == "check-replay" && argc == 3) return rig::check_replay(argv[2]);
    if (cmd == "check-firmware" && argc == 3) return rig::check_firmware_log(argv[2]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "can_rig: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr,
               "usage: can_rig frames | run IFACE SECONDS | check LOG | write-log FILE | "
               "check-replay LOG | check-firmware LOG\n");
  return 2;
}
