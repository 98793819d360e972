// SPDX-License-Identifier: MIT
#pragma once

// Guarded write of the calibration over CAN (messages 0x0A0-0x0A4, reply
// 0x0A8; firmware/can/README.md). A calibration changes what the gyro outputs,
// so the write is:
//   - accepted only in the service mode (Mode::safe: drives at zero, no output);
//   - behind a seed/key unlock in the manner of UDS SecurityAccess (0x27):
//     the host asks for a seed, answers key = calibration_key(seed, secret);
//     a seed is good for one attempt; max_attempts wrong keys lock the
//     service out for lockout_ms; an unlock lapses after unlock_timeout_ms;
//   - sent as one block: START (length, CRC-32), DATA frames with sequence
//     numbers 0, 1, ... of 7 bytes each, END;
//   - checked (length, sequence, CRC-32 of the canonical form, format version,
//     every field's physical range) and applied all-or-nothing at END;
//   - answered: every frame in the range gets an HRG_CAL_REPLY, except DATA
//     frames that are accepted (the block is answered at END).
// A partial, stale (no frame for frame_timeout_ms), out-of-range or
// unauthorised block changes nothing and is counted by its reply code.
// Freestanding: no heap, no exceptions; the firmware owns one instance and
// calls it from the command task.

#include <array>
#include <cstdint>

#include "firmware/calibration.hpp"
#include "firmware/mode.hpp"
#include "hal/can.hpp"

namespace hrg::fw::can {

inline constexpr uint32_t kCalSeedRequestId = 0x0A0;
inline constexpr uint32_t kCalKeyId = 0x0A1;
inline constexpr uint32_t kCalStartId = 0x0A2;
inline constexpr uint32_t kCalDataId = 0x0A3;
inline constexpr uint32_t kCalEndId = 0x0A4;
inline constexpr uint32_t kCalReplyId = 0x0A8;
inline constexpr unsigned kCalDataBytesPerFrame = 7;

// HRG_CAL_REPLY.result. Values are stable (DBC VAL_ table).
enum class CalResult : uint8_t {
  accepted = 0,
  bad_length = 1,     // DLC wrong, or a START length other than the canonical form's
  bad_checksum = 2,   // CRC-8 of a control frame
  wrong_state = 3,    // not in the service mode; detail = mode
  locked = 4,         // no valid seed, not unlocked, or no transfer open
  bad_key = 5,        // detail = attempts left
  locked_out = 6,     // too many wrong keys; detail = seconds left (rounded up)
  bad_sequence = 7,   // a DATA frame out of order; detail = the sequence number expected
  stale = 8,          // the open block timed out (sent on its own); detail = bytes received
  crc_mismatch = 9,   // CRC-32 of the received block differs from START's
  out_of_range = 10,  // detail = index of the first field out of range (kCalibrationFields)
  bad_format = 11,    // format version byte unknown
  incomplete = 12,    // END before all bytes arrived; detail = bytes received
  not_applied = 13,   // valid, but the firmware could not put it in force (the chain's formats)
};
inline constexpr std::size_t kCalResultCount = 14;
const char* to_string(CalResult r);

// Which frame a reply answers (HRG_CAL_REPLY.step).
enum class CalStep : uint8_t { seed = 0, key = 1, start = 2, data = 3, end = 4, timeout = 5 };

// key = the low 32 bits of SipHash-2-4 keyed with the 128-bit secret over the
// seed's 4 bytes, little-endian. The secret never goes on the bus.
using CalSecret = std::array<uint8_t, 16>;
uint32_t calibration_key(uint32_t seed, const CalSecret& secret);
// SipHash-2-4 (Aumasson and Bernstein), 64-bit output.
uint64_t siphash24(const CalSecret& key, const uint8_t* data, std::size_t n);

struct CalTransferConfig {
  CalSecret secret{};
  uint8_t max_attempts = 3;
  uint32_t lockout_ms = 10'000;
  uint32_t unlock_timeout_ms = 30'000;
  uint32_t frame_timeout_ms = 500;
};

struct CalTransferOutcome {
  bool for_us = false;       // identifier in 0x0A0-0x0A4
  bool reply_ready = false;  // `reply` holds an HRG_CAL_REPLY to send
  CalResult result = CalResult::accepted;
  uint8_t detail = 0;
  bool applied = false;  // a new calibration is active from now on
  hal::CanFrame reply{};
};

// Puts a checked calibration in force, all or nothing (false: the one in
// force stays). The firmware's one apply path, called at END from the
// command task: in the service mode, between two blocks of the chain.
using CalibrationApply = bool (*)(void* context, const Calibration& cal);

class CalibrationTransfer {
 public:
  CalibrationTransfer(const CalTransferConfig& cfg, const Calibration& active);

  // Where an accepted block goes (none: it only becomes active()), and the
  // calibration in force now (its CRC answers END).
  void set_apply(CalibrationApply apply, void* context) {
    apply_ = apply;
    apply_context_ = context;
  }
  void set_active(const Calibration& active);

  static bool is_calibration_id(uint32_t id) { return id >= kCalSeedRequestId && id <= kCalEndId; }

  // One received frame. `entropy` seeds the next seed (a free-running timer
  // or a hardware RNG on the board); `now_ms` is a wrapping millisecond clock.
  CalTransferOutcome process(const hal::CanFrame& f, Mode mode, uint32_t now_ms, uint32_t entropy);
  // Drops an open block that went stale, and a lapsed unlock. Returns true
  // (with `reply` filled: step timeout, result stale) when a block was dropped.
  // Also closes everything when the gyro has left the service mode.
  bool tick(uint32_t now_ms, Mode mode, hal::CanFrame& reply);

  const Calibration& active() const { return active_; }
  uint32_t active_crc() const { return active_crc_; }
  uint32_t applied_count() const { return applied_; }
  // Frames handled with each result (index = CalResult value; accepted DATA
  // frames count as accepted without a reply).
  const std::array<uint32_t, kCalResultCount>& counts() const { return counts_; }
  bool unlocked() const { return state_ == State::unlocked || state_ == State::receiving; }

 private:
  enum class State : uint8_t { idle, seed_sent, unlocked, receiving };

  CalTransferOutcome on_seed_request(uint32_t now_ms, uint32_t entropy);
  CalTransferOutcome on_key(const hal::CanFrame& f, uint32_t now_ms);
  CalTransferOutcome on_start(const hal::CanFrame& f, uint32_t now_ms);
  CalTransferOutcome on_data(const hal::CanFrame& f, uint32_t now_ms);
  CalTransferOutcome on_end(uint32_t now_ms);
  CalTransferOutcome answer(CalStep step, CalResult r, uint8_t detail, uint32_t value = 0);
  void drop_block();
  bool locked_out(uint32_t now_ms) const;

  CalTransferConfig cfg_;
  CalibrationApply apply_ = nullptr;
  void* apply_context_ = nullptr;
  Calibration active_;
  uint32_t active_crc_ = 0;
  State state_ = State::idle;
  uint32_t seed_ = 0;
  uint8_t attempts_left_;
  bool lockout_ = false;
  uint32_t lockout_start_ms_ = 0;
  uint32_t last_activity_ms_ = 0;  // unlock and block timeouts run from here
  CalibrationBytes block_{};
  uint32_t block_crc_ = 0;
  uint16_t received_ = 0;
  uint8_t next_seq_ = 0;
  uint32_t applied_ = 0;
  uint8_t reply_seq_ = 0;
  std::array<uint32_t, kCalResultCount> counts_{};
};

// Host side: the frames of a guarded write.
hal::CanFrame encode_cal_seed_request();
hal::CanFrame encode_cal_key(uint32_t key);
hal::CanFrame encode_cal_start(uint16_t length, uint32_t block_crc);
hal::CanFrame encode_cal_data(uint8_t seq, const uint8_t* bytes, unsigned n);
hal::CanFrame encode_cal_end();

struct CalReply {
  CalStep step = CalStep::seed;
  CalResult result = CalResult::accepted;
  uint8_t detail = 0;
  uint32_t value = 0;  // seed (seed step), active CRC-32 (end), 0 otherwise
  uint8_t seq = 0;
};
bool decode_cal_reply(const hal::CanFrame& f, CalReply& out);

}  // namespace hrg::fw::can
