// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>

#include "firmware/can/calibration_transfer.hpp"
#include "firmware/can/command.hpp"
#include "hal/can.hpp"

namespace hrg::fw::can {

// The firmware's side of the CAN bus, serviced once per base frame: receives
// and validates commands (answering every one), feeds the calibration
// service's frames (0x0A0-0x0A4) to its CalibrationTransfer, sends telemetry,
// and restarts the controller after it has been bus-off for a while. Never
// blocks; no heap. Calling context: the executive's CAN task only.
class CanLink {
 public:
  struct Stats {
    uint32_t commands_accepted = 0;
    uint32_t commands_refused = 0;
    uint32_t tx_refused = 0;  // telemetry or replies the bus did not take (full queue, bus-off)
    uint32_t restarts = 0;    // restart() calls made after bus-off
  };

  // `restart_after_frames`: base frames spent bus-off before restart() (the
  // controller's recovery sequence needs 128 x 11 recessive bits; waiting also
  // keeps a faulty bus from being hammered).
  explicit CanLink(hal::CanBus& bus, uint32_t restart_after_frames = 100,
                   const CalTransferConfig& calibration = {});

  // Receive only the command range 0x080-0x08F and the calibration service
  // 0x0A0-0x0A7. Call once at init.
  hal::Status init();

  // Handles received frames until one command is accepted (returned in `out`,
  // true) or nothing is left (false). Refused commands are answered and
  // dropped. One accepted command per call, so the next is validated against
  // the state after the firmware has applied this one. Calibration frames go
  // to the transfer (state.mode gates it; `now_ms` a wrapping millisecond
  // clock, `entropy` seeds its seed) and are answered as it says; a block
  // accepted at END is put in force through its apply hook right there.
  bool poll(const ControllerView& state, Command& out, uint32_t now_ms = 0, uint32_t entropy = 0);

  // The calibration service's timeouts (a stale block, a lapsed unlock,
  // leaving the service mode); answers a dropped block. Once per command run.
  void tick_calibration(uint32_t now_ms, Mode mode);

  // Sends frames; each refusal (would_block when the TX queue is full, bus_off)
  // is counted and the frame dropped: telemetry is never queued in software.
  void send(std::span<const hal::CanFrame> frames);

  // Bus-off recovery; call once per base frame.
  void service();

  const Stats& stats() const { return stats_; }
  const CommandValidator& validator() const { return validator_; }
  CalibrationTransfer& calibration() { return calibration_; }
  const CalibrationTransfer& calibration() const { return calibration_; }

 private:
  hal::CanBus& bus_;
  uint32_t restart_after_frames_;
  uint32_t off_frames_ = 0;
  CommandValidator validator_;
  CalibrationTransfer calibration_;
  Stats stats_;
};

}  // namespace hrg::fw::can
