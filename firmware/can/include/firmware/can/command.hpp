// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

#include "firmware/can/messages.hpp"
#include "firmware/mode.hpp"
#include "hal/can.hpp"

namespace hrg::fw::can {

// Result of a command, sent back in HRG_CMD_REPLY.result. Values are stable.
enum class CommandResult : uint8_t {
  accepted = 0,
  bad_length = 1,        // DLC differs from the DBC
  bad_checksum = 2,      // CRC-8 mismatch
  repeated_counter = 3,  // same counter as the last accepted command (replayed frame)
  out_of_range = 4,      // a value outside the DBC range; detail = signal index
  wrong_state = 5,       // not allowed in the current mode; detail = mode
  unsafe = 6,            // would put the resonator at risk; detail = reason (UnsafeReason)
  unknown_command = 7,   // identifier in the command range but no such command
  reserved_bits = 8,     // the reserved bits next to the counter are not zero
};

enum class UnsafeReason : uint8_t {
  none = 0,
  fault_active = 1,     // ring-up while a fault bit or the fault input is set
  window_too_long = 2,  // free-decay window longer than a quarter of the period
  set_point_step = 3,   // AGC set-point step above 25 % while operating
};

const char* to_string(CommandResult r);

// A decoded, validated command.
struct Command {
  Cmd id = Cmd::status_request;
  uint8_t counter = 0;
  Mode mode = Mode::safe;      // set_mode
  bool ident_start = false;    // ident
  double window_period_s = 0;  // window
  double window_length_s = 0;  // window
  double agc_setpoint_v = 0;   // agc
};

// What the validator needs to know about the controller.
struct ControllerView {
  Mode mode = Mode::power_up;
  uint16_t faults = 0;
  bool fault_input = false;
  bool ident_active = false;
  double agc_setpoint_v = 0;
  // False when this firmware build cannot change the window schedule, the AGC
  // set point or identification at run time: those commands are then refused
  // as wrong_state instead of being acknowledged and ignored.
  bool accepts_settings = true;
};

struct CommandOutcome {
  bool for_us = false;  // identifier in the command range; otherwise ignore the frame
  CommandResult result = CommandResult::unknown_command;
  uint8_t detail = 0;
  Command command{};      // valid only when result == accepted
  hal::CanFrame reply{};  // HRG_CMD_REPLY to send whenever for_us
};

// CRC-8 SAE J1850 (poly 0x1D, init 0xFF, final xor 0xFF) over the identifier
// (low byte, then high byte) and every data byte but the last; the last byte
// holds the CRC. Including the identifier stops a frame valid for one command
// from passing as another.
uint8_t command_crc8(uint32_t id, const uint8_t* data, uint8_t len_without_crc);

// Decodes and validates commands. A refused command changes nothing (not even
// the counter state) and produces an error reply; an accepted one returns the
// command for the firmware to apply and an `accepted` reply.
// Calling context: the executive's command task. No heap.
class CommandValidator {
 public:
  CommandOutcome process(const hal::CanFrame& frame, const ControllerView& state);
  // Counter of the last accepted command, or -1 before the first.
  int last_counter() const { return last_counter_; }

 private:
  hal::CanFrame make_reply(uint32_t id, uint8_t counter, CommandResult r, uint8_t detail);
  int last_counter_ = -1;
  uint8_t reply_seq_ = 0;
};

// Host side: builds a command frame with counter and CRC.
hal::CanFrame encode_set_mode(Mode mode, uint8_t counter);
hal::CanFrame encode_ident(bool start, uint8_t counter);
hal::CanFrame encode_window(double period_s, double length_s, uint8_t counter);
hal::CanFrame encode_agc(double setpoint_v, uint8_t counter);
hal::CanFrame encode_status_request(uint8_t counter);
// Recomputes the CRC of a command frame in place (host tools, tests).
void seal_command(hal::CanFrame& f);

// Host side: reads an HRG_CMD_REPLY. Returns false when the frame is not one.
struct Reply {
  uint8_t command_id = 0;  // low byte of the command's identifier
  uint8_t counter = 0;
  CommandResult result = CommandResult::accepted;
  uint8_t detail = 0;
  uint8_t seq = 0;
};
bool decode_reply(const hal::CanFrame& f, Reply& out);

}  // namespace hrg::fw::can
