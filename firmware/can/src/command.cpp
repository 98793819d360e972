// SPDX-License-Identifier: MIT
#include "firmware/can/command.hpp"

namespace hrg::fw::can {

namespace {

constexpr double kMaxWindowFraction = 0.25;  // free decay at most a quarter of the period
constexpr double kMaxSetPointStep = 0.25;    // relative AGC step allowed while operating

const MessageDef& def(Cmd c) { return kCommands[static_cast<std::size_t>(c)]; }

// Counter and CRC are the last two signals of every command.
const SignalDef& counter_sig(const MessageDef& m) { return m.signals[m.signals.size() - 2]; }

uint8_t reserved_nibble(const MessageDef& m, const hal::CanFrame& f) {
  const SignalDef& c = counter_sig(m);
  return static_cast<uint8_t>(get_bits(f, c.start_bit + kCounterBits, 4));
}

hal::CanFrame blank(Cmd c) {
  hal::CanFrame f;
  f.id = def(c).id;
  f.len = def(c).dlc;
  return f;
}

hal::CanFrame finish(hal::CanFrame f, uint8_t counter) {
  const SignalDef& c = counter_sig(*find_message(f.id));
  put_bits(f, c.start_bit, c.length, counter & 0x0Fu);
  seal_command(f);
  return f;
}

bool in_range(const SignalDef& s, const hal::CanFrame& f) {
  const double v = decode_signal(s, f);
  const double half_lsb = 0.5 * s.factor;
  return v >= s.min - half_lsb && v <= s.max + half_lsb;
}

// The result of one check and its reply detail.
struct Verdict {
  CommandResult result;
  uint8_t detail;
};
constexpr Verdict kAccepted{CommandResult::accepted, 0};

// Checks that need only the frame and the counter state, in the documented
// order: length, CRC, reserved bits, counter, every payload value in its DBC
// range. `counter` is set once the CRC holds (the reply echoes it).
Verdict check_frame(const MessageDef& m, const hal::CanFrame& frame, int last_counter,
                    uint8_t& counter) {
  if (frame.len != m.dlc) return {CommandResult::bad_length, frame.len};
  if (command_crc8(frame.id, frame.data.data(), static_cast<uint8_t>(m.dlc - 1)) !=
      frame.data[m.dlc - 1]) {
    return {CommandResult::bad_checksum, 0};
  }
  counter = static_cast<uint8_t>(decode_raw(counter_sig(m), frame));
  if (reserved_nibble(m, frame) != 0) return {CommandResult::reserved_bits, 0};
  if (static_cast<int>(counter) == last_counter) return {CommandResult::repeated_counter, 0};
  for (std::size_t i = 0; i + 2 < m.signals.size(); ++i) {
    if (!in_range(m.signals[i], frame)) {
      return {CommandResult::out_of_range, static_cast<uint8_t>(i)};
    }
  }
  return kAccepted;
}

Verdict wrong_state(const ControllerView& st) {
  return {CommandResult::wrong_state, static_cast<uint8_t>(st.mode)};
}

Verdict unsafe(UnsafeReason r) { return {CommandResult::unsafe, static_cast<uint8_t>(r)}; }

Verdict check_set_mode(const MessageDef& m, const hal::CanFrame& frame, const ControllerView& st,
                       Command& c) {
  c.mode = static_cast<Mode>(decode_raw(m.signals[sig::target_mode], frame));
  // The controller reaches the other modes itself; only these are commandable.
  if (c.mode != Mode::safe && c.mode != Mode::ring_up) {
    return {CommandResult::out_of_range, sig::target_mode};
  }
  if (c.mode == Mode::ring_up) {
    if (st.mode != Mode::safe && st.mode != Mode::fault) return wrong_state(st);
    if (st.faults != 0 || st.fault_input) return unsafe(UnsafeReason::fault_active);
  }
  return kAccepted;
}

Verdict check_window(const MessageDef& m, const hal::CanFrame& frame, const ControllerView& st,
                     Command& c) {
  c.window_period_s = decode_signal(m.signals[sig::period_s], frame);
  c.window_length_s = decode_signal(m.signals[sig::length_s], frame);
  if (st.mode == Mode::free_decay) return wrong_state(st);
  // Half an LSB of slack so a length of exactly a quarter passes.
  if (c.window_length_s >
      kMaxWindowFraction * c.window_period_s + 0.5 * m.signals[sig::length_s].factor) {
    return unsafe(UnsafeReason::window_too_long);
  }
  return kAccepted;
}

Verdict check_agc(const MessageDef& m, const hal::CanFrame& frame, const ControllerView& st,
                  Command& c) {
  c.agc_setpoint_v = decode_signal(m.signals[sig::setpoint_v], frame);
  if (st.mode == Mode::free_decay) return wrong_state(st);
  const double step = c.agc_setpoint_v - st.agc_setpoint_v;
  const double allowed =
      kMaxSetPointStep * st.agc_setpoint_v + 0.5 * m.signals[sig::setpoint_v].factor;
  if (st.mode == Mode::operate && (step > allowed || -step > allowed)) {
    return unsafe(UnsafeReason::set_point_step);
  }
  return kAccepted;
}

// The mode and safety rules of a well-formed command; fills its payload.
Verdict check_rules(const MessageDef& m, const hal::CanFrame& frame, const ControllerView& st,
                    Command& c) {
  const bool is_setting = c.id == Cmd::ident || c.id == Cmd::window || c.id == Cmd::agc;
  if (is_setting && !st.accepts_settings) return wrong_state(st);
  switch (c.id) {
    case Cmd::set_mode: return check_set_mode(m, frame, st, c);
    case Cmd::ident:
      c.ident_start = decode_raw(m.signals[sig::action], frame) == 1;
      if (c.ident_start ? (st.mode != Mode::operate || st.ident_active) : !st.ident_active) {
        return wrong_state(st);
      }
      return kAccepted;
    case Cmd::window: return check_window(m, frame, st, c);
    case Cmd::agc: return check_agc(m, frame, st, c);
    case Cmd::status_request: return kAccepted;
  }
  return {CommandResult::unknown_command, 0};
}

}  // namespace

const char* to_string(CommandResult r) {
  switch (r) {
    case CommandResult::accepted: return "accepted";
    case CommandResult::bad_length: return "bad_length";
    case CommandResult::bad_checksum: return "bad_checksum";
    case CommandResult::repeated_counter: return "repeated_counter";
    case CommandResult::out_of_range: return "out_of_range";
    case CommandResult::wrong_state: return "wrong_state";
    case CommandResult::unsafe: return "unsafe";
    case CommandResult::unknown_command: return "unknown_command";
    case CommandResult::reserved_bits: return "reserved_bits";
  }
  return "unknown";
}

uint8_t command_crc8(uint32_t id, const uint8_t* data, uint8_t len_without_crc) {
  uint8_t crc = 0xFF;
  auto feed = [&crc](uint8_t byte) {
    crc = static_cast<uint8_t>(crc ^ byte);
    for (int i = 0; i < 8; ++i) {
      crc =
          (crc & 0x80u) ? static_cast<uint8_t>((crc << 1) ^ 0x1Du) : static_cast<uint8_t>(crc << 1);
    }
  };
  feed(static_cast<uint8_t>(id & 0xFFu));
  feed(static_cast<uint8_t>((id >> 8) & 0xFFu));
  for (uint8_t i = 0; i < len_without_crc; ++i)
    feed(data[i]);
  return static_cast<uint8_t>(crc ^ 0xFFu);
}

void seal_command(hal::CanFrame& f) {
  if (f.len == 0 || f.len > 8) return;
  f.data[f.len - 1] = command_crc8(f.id, f.data.data(), static_cast<uint8_t>(f.len - 1));
}

hal::CanFrame CommandValidator::make_reply(uint32_t id, uint8_t counter, CommandResult r,
                                           uint8_t detail) {
  hal::CanFrame f;
  f.id = kReply.id;
  f.len = kReply.dlc;
  put_bits(f, kReply.signals[sig::command_id].start_bit, 8, id & 0xFFu);
  put_bits(f, kReply.signals[sig::reply_counter].start_bit, 4, counter);
  put_bits(f, kReply.signals[sig::result].start_bit, 4, static_cast<uint8_t>(r));
  put_bits(f, kReply.signals[sig::detail].start_bit, 8, detail);
  put_bits(f, kReply.signals[sig::reply_seq].start_bit, 8, reply_seq_);
  reply_seq_ = static_cast<uint8_t>(reply_seq_ + 1u);
  return f;
}

CommandOutcome CommandValidator::process(const hal::CanFrame& frame, const ControllerView& st) {
  CommandOutcome out;
  if (frame.extended || frame.id < kCommandIdFirst || frame.id > kCommandIdLast) return out;
  out.for_us = true;
  const std::size_t index = frame.id - kCommandIdFirst;
  uint8_t counter = 0;
  Verdict v{CommandResult::unknown_command, 0};
  if (index < kCommandCount) {
    v = check_frame(kCommands[index], frame, last_counter_, counter);
    if (v.result == CommandResult::accepted) {
      out.command.id = static_cast<Cmd>(index);
      out.command.counter = counter;
      v = check_rules(kCommands[index], frame, st, out.command);
    }
  }
  out.result = v.result;
  out.detail = v.detail;
  out.reply = make_reply(frame.id, counter, v.result, v.detail);
  if (v.result == CommandResult::accepted) {
    last_counter_ = counter;
  } else {
    out.command = Command{};
  }
  return out;
}

hal::CanFrame encode_set_mode(Mode mode, uint8_t counter) {
  hal::CanFrame f = blank(Cmd::set_mode);
  put_bits(f, 0, 8, static_cast<uint8_t>(mode));
  return finish(f, counter);
}

hal::CanFrame encode_ident(bool start, uint8_t counter) {
  hal::CanFrame f = blank(Cmd::ident);
  put_bits(f, 0, 8, start ? 1u : 0u);
  return finish(f, counter);
}

hal::CanFrame encode_window(double period_s, double length_s, uint8_t counter) {
  hal::CanFrame f = blank(Cmd::window);
  const MessageDef& m = def(Cmd::window);
  encode_signal(m.signals[sig::period_s], period_s, f);
  encode_signal(m.signals[sig::length_s], length_s, f);
  return finish(f, counter);
}

hal::CanFrame encode_agc(double setpoint_v, uint8_t counter) {
  hal::CanFrame f = blank(Cmd::agc);
  encode_signal(def(Cmd::agc).signals[sig::setpoint_v], setpoint_v, f);
  return finish(f, counter);
}

hal::CanFrame encode_status_request(uint8_t counter) {
  return finish(blank(Cmd::status_request), counter);
}

bool decode_reply(const hal::CanFrame& f, Reply& out) {
  if (f.extended || f.id != kReply.id || f.len != kReply.dlc) return false;
  out.command_id = static_cast<uint8_t>(decode_raw(kReply.signals[sig::command_id], f));
  out.counter = static_cast<uint8_t>(decode_raw(kReply.signals[sig::reply_counter], f));
  out.result = static_cast<CommandResult>(decode_raw(kReply.signals[sig::result], f));
  out.detail = static_cast<uint8_t>(decode_raw(kReply.signals[sig::detail], f));
  out.seq = static_cast<uint8_t>(decode_raw(kReply.signals[sig::reply_seq], f));
  return true;
}

}  // namespace hrg::fw::can
