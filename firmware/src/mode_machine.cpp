// SPDX-License-Identifier: MIT
#include "firmware/mode_machine.hpp"

namespace hrg::fw {

const char* to_string(Mode m) {
  switch (m) {
    case Mode::power_up: return "power_up";
    case Mode::ring_up: return "ring_up";
    case Mode::lock: return "lock";
    case Mode::operate: return "operate";
    case Mode::free_decay: return "free_decay";
    case Mode::recover: return "recover";
    case Mode::fault: return "fault";
    case Mode::safe: return "safe";
  }
  return "unknown";
}

const char* to_string(Event e) {
  switch (e) {
    case Event::self_test_passed: return "self_test_passed";
    case Event::amplitude_reached: return "amplitude_reached";
    case Event::loops_settled: return "loops_settled";
    case Event::window_open: return "window_open";
    case Event::window_close: return "window_close";
    case Event::reacquired: return "reacquired";
    case Event::fault_detected: return "fault_detected";
    case Event::fault_cleared: return "fault_cleared";
    case Event::retries_exhausted: return "retries_exhausted";
    case Event::command_safe: return "command_safe";
    case Event::command_restart: return "command_restart";
    case Event::count_: break;
  }
  return "unknown";
}

bool ModeMachine::go(Mode to) {
  if (to == mode_) return false;
  mode_ = to;
  ++transitions_;
  if (to == Mode::operate) {
    // A clean pass through lock or recover ends the fault episode.
    retries_ = 0;
    faults_ = 0;
  }
  return true;
}

bool ModeMachine::handle(Event e, uint16_t fault_bits) {
  if (e == Event::fault_detected) {
    faults_ = static_cast<uint16_t>(faults_ | fault_bits);
    if ((fault_bits & kSevereFaults) != 0 && mode_ != Mode::safe) return go(Mode::safe);
  }
  if (e == Event::fault_cleared && mode_ == Mode::fault) {
    // Recovery is attempted a bounded number of times; then drives stay off.
    if (retries_ >= max_retries_) return go(Mode::safe);
    ++retries_;
  }
  if (e == Event::command_restart && mode_ == Mode::safe) {
    faults_ = 0;
    retries_ = 0;
  }
  Mode to = mode_;
  if (!lookup_transition(mode_, e, to)) {
    ++ignored_;
    return false;
  }
  return go(to);
}

}  // namespace hrg::fw
