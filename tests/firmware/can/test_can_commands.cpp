// SPDX-License-Identifier: MIT
// Command validation: every refusal path gives its error reply and changes
// nothing; accepted commands come back decoded.
#include <cstdint>

#include "firmware/can/command.hpp"

#include "support/cpputest.hpp"

using namespace hrg::fw::can;
using hrg::fw::Mode;
using hrg::hal::CanFrame;

namespace {

ControllerView operating() {
  ControllerView v;
  v.mode = Mode::operate;
  v.agc_setpoint_v = 1.0;
  return v;
}

ControllerView in_mode(Mode m) {
  ControllerView v = operating();
  v.mode = m;
  return v;
}

}  // namespace

TEST_GROUP(CommandValidator) {
  CommandValidator validator;

  // Runs a frame; checks the result, the reply and that a refusal changed nothing.
  CommandOutcome expect(const CanFrame& f, const ControllerView& st, CommandResult r,
                        uint8_t detail = 0) {
    const int counter_before = validator.last_counter();
    CommandOutcome out = validator.process(f, st);
    CHECK(out.for_us);
    STRCMP_EQUAL(to_string(r), to_string(out.result));
    LONGS_EQUAL(detail, out.detail);
    Reply reply;
    CHECK(decode_reply(out.reply, reply));
    LONGS_EQUAL(f.id & 0xFFu, reply.command_id);
    LONGS_EQUAL(static_cast<int>(r), static_cast<int>(reply.result));
    LONGS_EQUAL(detail, reply.detail);
    if (r != CommandResult::accepted) LONGS_EQUAL(counter_before, validator.last_counter());
    return out;
  }
};

TEST(CommandValidator, Crc8IsSaeJ1850OverIdentifierAndData) {
  // The SAE J1850 check value: CRC of "123456789" is 0x4B. The identifier
  // supplies the first two bytes ('1' low, '2' high).
  const uint8_t rest[] = {'3', '4', '5', '6', '7', '8', '9'};
  LONGS_EQUAL(0x4B, command_crc8(0x3231, rest, 7));
}

TEST(CommandValidator, FramesOutsideTheCommandRangeAreNotOurs) {
  CanFrame f = encode_status_request(1);
  f.id = 0x100;
  CHECK_FALSE(validator.process(f, operating()).for_us);
  f = encode_status_request(1);
  f.extended = true;  // 29-bit 0x084 is another identifier
  CHECK_FALSE(validator.process(f, operating()).for_us);
}

TEST(CommandValidator, AnUnknownIdentifierInTheCommandRangeIsRefused) {
  CanFrame f = encode_status_request(1);
  f.id = 0x085;
  seal_command(f);
  expect(f, operating(), CommandResult::unknown_command);
  f.id = 0x08F;
  seal_command(f);
  expect(f, operating(), CommandResult::unknown_command);
}

TEST(CommandValidator, AWrongLengthIsRefusedForEveryCommand) {
  const CanFrame frames[] = {encode_set_mode(Mode::safe, 1), encode_ident(true, 1),
                             encode_window(60, 2, 1), encode_agc(1.0, 1), encode_status_request(1)};
  for (CanFrame f : frames) {
    const uint8_t dlc = f.len;
    f.len = static_cast<uint8_t>(dlc - 1);
    expect(f, operating(), CommandResult::bad_length, f.len);
    f.len = static_cast<uint8_t>(dlc + 1);
    expect(f, operating(), CommandResult::bad_length, f.len);
  }
}

TEST(CommandValidator, ACorruptedFrameFailsTheChecksum) {
  const CanFrame frames[] = {encode_set_mode(Mode::safe, 1), encode_ident(true, 1),
                             encode_window(60, 2, 1), encode_agc(1.0, 1), encode_status_request(1)};
  for (CanFrame f : frames) {
    f.data[0] ^= 0x04;
    expect(f, operating(), CommandResult::bad_checksum);
  }
  // A frame valid for one identifier does not pass as another.
  CanFrame f = encode_ident(true, 2);
  f.id = 0x080;
  expect(f, operating(), CommandResult::bad_checksum);
}

TEST(CommandValidator, ReservedBitsBesideTheCounterMustBeZero) {
  CanFrame f = encode_agc(1.1, 5);
  f.data[2] = static_cast<uint8_t>(f.data[2] | 0x10);
  seal_command(f);
  expect(f, operating(), CommandResult::reserved_bits);
}

TEST(CommandValidator, ARepeatedCounterIsRefusedAndTheNextCounterAccepted) {
  expect(encode_status_request(3), operating(), CommandResult::accepted);
  LONGS_EQUAL(3, validator.last_counter());
  expect(encode_agc(1.1, 3), operating(), CommandResult::repeated_counter);
  expect(encode_agc(1.1, 4), operating(), CommandResult::accepted);
  LONGS_EQUAL(4, validator.last_counter());
}

TEST(CommandValidator, ValuesOutsideTheDbcRangeAreRefusedNamingTheSignal) {
  // Mode 8 is outside [0, 7]; action 2 outside [0, 1].
  CanFrame f = encode_set_mode(Mode::safe, 1);
  f.data[0] = 8;
  seal_command(f);
  expect(f, operating(), CommandResult::out_of_range, sig::target_mode);
  f = encode_ident(true, 1);
  f.data[0] = 2;
  seal_command(f);
  expect(f, operating(), CommandResult::out_of_range, sig::action);
  // Window period [1, 3600] s in 0.1 s steps; length [0.01, 5] s in 1 ms steps.
  f = encode_window(60, 1, 1);
  f.data[0] = 9;  // 0.9 s
  f.data[1] = 0;
  seal_command(f);
  expect(f, operating(), CommandResult::out_of_range, sig::period_s);
  f.data[0] = 0xA1;  // 36001 = 3600.1 s
  f.data[1] = 0x8C;
  seal_command(f);
  expect(f, operating(), CommandResult::out_of_range, sig::period_s);
  f = encode_window(60, 1, 1);
  f.data[2] = 9;  // 9 ms
  f.data[3] = 0;
  seal_command(f);
  expect(f, operating(), CommandResult::out_of_range, sig::length_s);
  f.data[2] = 0x89;  // 5001 ms
  f.data[3] = 0x13;
  seal_command(f);
  expect(f, operating(), CommandResult::out_of_range, sig::length_s);
  // AGC set point [0.05, 2] V in 0.1 mV steps: 499 and 20001 are outside.
  f = encode_agc(1.0, 1);
  f.data[0] = 0xF3;
  f.data[1] = 0x01;
  seal_command(f);
  expect(f, operating(), CommandResult::out_of_range, sig::setpoint_v);
  f.data[0] = 0x21;
  f.data[1] = 0x4E;
  seal_command(f);
  expect(f, operating(), CommandResult::out_of_range, sig::setpoint_v);
}

TEST(CommandValidator, OnlySafeAndRingUpAreCommandableModes) {
  const Mode internal[] = {Mode::power_up,   Mode::lock,    Mode::operate,
                           Mode::free_decay, Mode::recover, Mode::fault};
  uint8_t counter = 0;
  for (Mode m : internal) {
    expect(encode_set_mode(m, ++counter), in_mode(Mode::safe), CommandResult::out_of_range,
           sig::target_mode);
  }
}

TEST(CommandValidator, CommandsNotAllowedInTheCurrentModeAreRefused) {
  expect(encode_set_mode(Mode::ring_up, 1), operating(), CommandResult::wrong_state,
         static_cast<uint8_t>(Mode::operate));
  expect(encode_ident(true, 1), in_mode(Mode::lock), CommandResult::wrong_state,
         static_cast<uint8_t>(Mode::lock));
  ControllerView running = operating();
  running.ident_active = true;
  expect(encode_ident(true, 1), running, CommandResult::wrong_state,
         static_cast<uint8_t>(Mode::operate));
  expect(encode_ident(false, 1), operating(), CommandResult::wrong_state,
         static_cast<uint8_t>(Mode::operate));
  expect(encode_window(60, 2, 1), in_mode(Mode::free_decay), CommandResult::wrong_state,
         static_cast<uint8_t>(Mode::free_decay));
  expect(encode_agc(1.0, 1), in_mode(Mode::free_decay), CommandResult::wrong_state,
         static_cast<uint8_t>(Mode::free_decay));
}

TEST(CommandValidator, SettingsAreRefusedByAFirmwareThatCannotChangeThemAtRunTime) {
  ControllerView fixed = operating();
  fixed.accepts_settings = false;
  const uint8_t mode = static_cast<uint8_t>(Mode::operate);
  expect(encode_ident(true, 1), fixed, CommandResult::wrong_state, mode);
  expect(encode_window(60, 2, 1), fixed, CommandResult::wrong_state, mode);
  expect(encode_agc(1.1, 1), fixed, CommandResult::wrong_state, mode);
  expect(encode_set_mode(Mode::safe, 1), fixed, CommandResult::accepted);
  expect(encode_status_request(2), fixed, CommandResult::accepted);
}

TEST(CommandValidator, UnsafeCommandsAreRefusedWithTheirReason) {
  ControllerView faulted = in_mode(Mode::safe);
  faulted.faults = hrg::fw::fault_bit(hrg::fw::Fault::dac_fault);
  expect(encode_set_mode(Mode::ring_up, 1), faulted, CommandResult::unsafe,
         static_cast<uint8_t>(UnsafeReason::fault_active));
  ControllerView input = in_mode(Mode::fault);
  input.fault_input = true;
  expect(encode_set_mode(Mode::ring_up, 1), input, CommandResult::unsafe,
         static_cast<uint8_t>(UnsafeReason::fault_active));
  // 2.51 s of free decay in a 10 s period is above the quarter.
  expect(encode_window(10, 2.51, 1), operating(), CommandResult::unsafe,
         static_cast<uint8_t>(UnsafeReason::window_too_long));
  // From 1.0 V a step to 1.26 V or 0.74 V is above 25 %.
  expect(encode_agc(1.26, 1), operating(), CommandResult::unsafe,
         static_cast<uint8_t>(UnsafeReason::set_point_step));
  expect(encode_agc(0.74, 1), operating(), CommandResult::unsafe,
         static_cast<uint8_t>(UnsafeReason::set_point_step));
  LONGS_EQUAL(-1, validator.last_counter());
}

TEST(CommandValidator, AcceptedCommandsComeBackDecoded) {
  CommandOutcome o = expect(encode_set_mode(Mode::safe, 1), operating(), CommandResult::accepted);
  CHECK(o.command.id == Cmd::set_mode);
  CHECK(o.command.mode == Mode::safe);
  o = expect(encode_set_mode(Mode::ring_up, 2), in_mode(Mode::safe), CommandResult::accepted);
  CHECK(o.command.mode == Mode::ring_up);
  o = expect(encode_ident(true, 3), operating(), CommandResult::accepted);
  CHECK(o.command.ident_start);
  ControllerView running = operating();
  running.ident_active = true;
  o = expect(encode_ident(false, 4), running, CommandResult::accepted);
  CHECK_FALSE(o.command.ident_start);
  // Exactly a quarter is allowed.
  o = expect(encode_window(20, 5, 5), operating(), CommandResult::accepted);
  DOUBLES_EQUAL(20.0, o.command.window_period_s, 1e-9);
  DOUBLES_EQUAL(5.0, o.command.window_length_s, 1e-9);
  o = expect(encode_agc(1.25, 6), operating(), CommandResult::accepted);
  DOUBLES_EQUAL(1.25, o.command.agc_setpoint_v, 1e-9);
  // Outside operate any in-range set point is accepted.
  o = expect(encode_agc(0.05, 7), in_mode(Mode::safe), CommandResult::accepted);
  DOUBLES_EQUAL(0.05, o.command.agc_setpoint_v, 1e-9);
  o = expect(encode_status_request(8), in_mode(Mode::fault), CommandResult::accepted);
  CHECK(o.command.id == Cmd::status_request);
  LONGS_EQUAL(8, validator.last_counter());
}

TEST(CommandValidator, RepliesCarryTheCounterAndARollingSequence) {
  const CommandOutcome a = validator.process(encode_status_request(9), operating());
  const CommandOutcome b = validator.process(encode_status_request(9), operating());
  Reply ra;
  Reply rb;
  CHECK(decode_reply(a.reply, ra));
  CHECK(decode_reply(b.reply, rb));
  LONGS_EQUAL(9, ra.counter);
  LONGS_EQUAL(9, rb.counter);
  LONGS_EQUAL(static_cast<int>(CommandResult::repeated_counter), static_cast<int>(rb.result));
  LONGS_EQUAL((ra.seq + 1) % 256, rb.seq);
}
