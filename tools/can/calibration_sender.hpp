// SPDX-License-Identifier: MIT
#pragma once

// The host's side of the guarded calibration write (firmware/can/README.md,
// "Calibration service"): seed request, key, START, DATA x 15, END, each
// control frame answered by HRG_CAL_REPLY. Over any bus the caller wraps in a
// CalBusIo: SocketCAN for `hrg can-calibrate`, the simulated target in tests.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "firmware/calibration.hpp"
#include "firmware/can/calibration_transfer.hpp"
#include "hal/can.hpp"

namespace hrg::can {

class CalBusIo {
 public:
  virtual ~CalBusIo() = default;
  virtual void send(const hal::CanFrame& f) = 0;
  // The next HRG_CAL_REPLY within `timeout_ms` (other frames skipped); false
  // when none came.
  virtual bool wait_reply(fw::can::CalReply& r, uint32_t timeout_ms) = 0;
  // Lets `ms` pass without sending.
  virtual void pause(uint32_t ms) = 0;
};

// What a test makes go wrong on purpose (each must be refused by the gyro).
struct CalWriteFaults {
  bool wrong_key = false;
  bool wrong_block_crc = false;  // START announces a CRC-32 the block does not have
  int skip_data_seq = -1;        // leave out this DATA frame
  int stop_after_data = -1;      // END after this many DATA frames
  uint32_t pause_before_end_ms = 0;
};

struct CalWriteResult {
  fw::can::CalReply reply{};  // the reply that ended the write
  bool answered = false;      // false: no reply within the timeout (`reply` is empty)
  bool applied() const {
    return answered && reply.step == fw::can::CalStep::end &&
           reply.result == fw::can::CalResult::accepted;
  }
};

inline constexpr uint32_t kCalReplyTimeoutMs = 200;

// Writes `cal` (canonical form, CRC-32) with the key derived from the
// gyro's seed and `secret`. Stops at the first refusal (a refused DATA frame
// is answered at once, so it is read before END).
CalWriteResult write_calibration(CalBusIo& io, const fw::Calibration& cal,
                                 const fw::can::CalSecret& secret,
                                 const CalWriteFaults& faults = {});

// 32 hex digits (the 128-bit secret, byte 0 first); false on anything else.
bool parse_secret(std::string_view hex, fw::can::CalSecret& out);

// `hrg can-calibrate FILE.toml --interface IF --secret HEX [--log OUT.log]`.
int can_calibrate_main(std::span<char* const> args);

}  // namespace hrg::can
