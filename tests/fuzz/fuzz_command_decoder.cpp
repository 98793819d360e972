// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary frames (any identifier, length 0..15, any data)
// and controller states through the command validator and the telemetry
// decoders. Besides crashes and sanitizer findings it checks the contract:
// a refused command leaves the counter state unchanged, an accepted one has
// every value inside its DBC range, and every frame in the command range gets
// a well-formed reply.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "firmware/can/command.hpp"
#include "firmware/can/messages.hpp"

using namespace hrg::fw::can;

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

bool within(double v, double lo, double hi) { return v >= lo - 1e-9 && v <= hi + 1e-9; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  ControllerView view;
  view.mode = static_cast<hrg::fw::Mode>(data[0] % 8);
  view.fault_input = (data[1] & 1) != 0;
  view.ident_active = (data[1] & 2) != 0;
  view.faults = (data[1] & 4) != 0 ? 1 : 0;
  view.accepts_settings = (data[1] & 8) == 0;
  view.agc_setpoint_v = 0.05 + (data[2] | (data[3] << 8)) * 3e-5;
  data += 4;
  size -= 4;
  CommandValidator validator;
  // Each frame: 2 bytes identifier (bit 15 picks the command range), 1 byte
  // length, 8 bytes data.
  while (size >= 11) {
    hrg::hal::CanFrame f;
    const unsigned raw_id = data[0] | (data[1] << 8);
    f.id = (raw_id & 0x8000u) != 0 ? kCommandIdFirst + (raw_id & 0x0Fu) : raw_id & 0x7FFu;
    f.extended = (raw_id & 0x4000u) != 0 && (raw_id & 0x8000u) == 0;
    f.len = static_cast<uint8_t>(data[2] % 16);
    for (int i = 0; i < 8; ++i)
      f.data[i] = data[3 + i];
    // Half the time make the checksum right so the deeper checks are reached.
    if ((data[2] & 0x80u) != 0) seal_command(f);
    data += 11;
    size -= 11;

    const int counter_before = validator.last_counter();
    const CommandOutcome o = validator.process(f, view);
    const bool in_range = !f.extended && f.id >= kCommandIdFirst && f.id <= kCommandIdLast;
    require(o.for_us == in_range);
    if (!o.for_us) continue;
    Reply r;
    require(decode_reply(o.reply, r));
    require(r.result == o.result && r.command_id == (f.id & 0xFFu));
    if (o.result != CommandResult::accepted) {
      require(validator.last_counter() == counter_before);
      continue;
    }
    require(validator.last_counter() == o.command.counter);
    switch (o.command.id) {
      case Cmd::set_mode:
        require(o.command.mode == hrg::fw::Mode::safe || o.command.mode == hrg::fw::Mode::ring_up);
        break;
      case Cmd::window:
        require(within(o.command.window_period_s, 1, 3600));
        require(within(o.command.window_length_s, 0.01, 5));
        require(o.command.window_length_s <= 0.25 * o.command.window_period_s + 1e-3);
        break;
      case Cmd::agc: require(within(o.command.agc_setpoint_v, 0.05, 2)); break;
      case Cmd::ident:
      case Cmd::status_request: break;
    }
    // Telemetry decoders over the same bytes.
    if (const MessageDef* m = find_message(f.id | 0x100u)) {
      for (const auto& s : m->signals)
        (void)decode_signal(s, f);
    }
  }
  return 0;
}
