// SPDX-License-Identifier: MIT
// `hrg can-calibrate FILE.toml --interface IF --secret HEX [--log OUT.log]`:
// writes a calibration file (hrg audit --calibration) into a gyro over
// SocketCAN through the guarded write, and says what the gyro answered.
#include <time.h>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "can/calibration_sender.hpp"
#include "can/candump_log.hpp"
#include "firmware/calibration_file.hpp"
#include "hal/linux/socket_can.hpp"

namespace hrg::can {

namespace {

uint64_t wall_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1'000'000'000ull + static_cast<uint64_t>(ts.tv_nsec);
}

void sleep_ms(uint32_t ms) {
  timespec ts{static_cast<time_t>(ms / 1000), static_cast<long>(ms % 1000) * 1'000'000L};
  nanosleep(&ts, nullptr);
}

// The guarded write over a SocketCAN interface, every frame both ways in an
// optional candump -l log.
class SocketCanIo final : public CalBusIo {
 public:
  SocketCanIo(hal::linux_board::SocketCan& bus, CandumpLogWriter* log) : bus_(bus), log_(log) {}
  void send(const hal::CanFrame& f) override {
    // A full TX queue empties in well under a millisecond at 1 Mbit/s.
    for (int i = 0; i < 100 && bus_.send(f) == hal::Status::would_block; ++i)
      sleep_ms(1);
    if (log_) log_->write(f, wall_ns());
  }
  bool wait_reply(fw::can::CalReply& r, uint32_t timeout_ms) override {
    for (uint32_t waited = 0;; ++waited) {
      hal::CanFrame f;
      while (bus_.receive(f) == hal::Status::ok) {
        if (log_) log_->write(f, wall_ns());
        if (fw::can::decode_cal_reply(f, r)) return true;
      }
      if (waited >= timeout_ms) return false;
      sleep_ms(1);
    }
  }
  void pause(uint32_t ms) override { sleep_ms(ms); }

 private:
  hal::linux_board::SocketCan& bus_;
  CandumpLogWriter* log_;
};

int usage() {
  std::fprintf(stderr,
               "usage: hrg can-calibrate FILE.toml --interface IF --secret HEX [--log OUT.log]\n"
               "Writes the calibration into the gyro on IF (it must be in its service mode,\n"
               "safe): seed/key unlock with the gyro's 128-bit secret (32 hex digits), the\n"
               "block under its CRC-32, all or nothing. --log records the exchange as a\n"
               "candump -l log. Exit status: 0 applied, 1 refused, 2 bad usage or input.\n");
  return 2;
}

}  // namespace

int can_calibrate_main(std::span<char* const> args) {
  std::string file, interface, secret_hex, log_path;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string a = args[i];
    const bool has_value = i + 1 < args.size();
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if (a == "--interface" && has_value) {
      interface = args[++i];
    } else if (a == "--secret" && has_value) {
      secret_hex = args[++i];
    } else if (a == "--log" && has_value) {
      log_path = args[++i];
    } else if (!a.empty() && a[0] != '-' && file.empty()) {
      file = a;
    } else {
      std::fprintf(stderr, "hrg can-calibrate: unexpected argument '%s'\n", args[i]);
      return usage();
    }
  }
  if (file.empty() || interface.empty() || secret_hex.empty()) return usage();
  fw::can::CalSecret secret{};
  if (!parse_secret(secret_hex, secret)) {
    std::fprintf(stderr, "hrg can-calibrate: --secret needs 32 hex digits\n");
    return 2;
  }
  try {
    const fw::CalibrationFile cal = fw::load_calibration(file);
    hal::linux_board::SocketCan bus;
    if (bus.open(interface.c_str()) != hal::Status::ok)
      throw std::runtime_error("cannot open CAN interface '" + interface + "'");
    const hal::CanFilter replies[] = {{fw::can::kCalReplyId, 0x7FF}};
    (void)bus.set_filters(replies);
    std::unique_ptr<CandumpLogWriter> log;
    if (!log_path.empty()) log = std::make_unique<CandumpLogWriter>(log_path, interface);
    SocketCanIo io(bus, log.get());
    const CalWriteResult r = write_calibration(io, cal.calibration, secret);
    if (log) log->flush();
    const uint32_t crc = fw::calibration_crc(cal.calibration);
    if (!r.answered) {
      std::printf("can-calibrate: no answer from the gyro on %s\n", interface.c_str());
      return 1;
    }
    std::printf("can-calibrate: step %u %s (detail %u); file CRC-32 %08x, gyro's %08x\n",
                static_cast<unsigned>(r.reply.step), fw::can::to_string(r.reply.result),
                static_cast<unsigned>(r.reply.detail), crc, r.reply.value);
    return r.applied() && r.reply.value == crc ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg can-calibrate: %s\n", e.what());
    return 2;
  }
}

}  // namespace hrg::can
