// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/mode.hpp"

namespace hrg::fw {

// What makes the mode machine move. Produced by the firmware's monitors, the
// interval shutdown scheduler and commands (CAN or host).
enum class Event : uint8_t {
  self_test_passed = 0,  // power_up: converters answer, ADC not stuck, no fault input
  amplitude_reached,     // ring_up: wave amplitude at the AGC set point band
  loops_settled,         // lock: PLL, AGC and quadrature errors inside their bands
  window_open,           // operate: the scheduler starts a free-decay window
  window_close,          // free_decay: the window has run its length
  reacquired,            // recover: loops back inside their bands after the window
  fault_detected,        // any monitor raised a fault bit (see Fault)
  fault_cleared,         // fault: the cause has gone for the hold time
  retries_exhausted,     // fault: too many recoveries in a row
  command_safe,          // operator or host: drives off now
  command_restart,       // operator or host: leave safe, start again
  count_
};

inline constexpr std::size_t kEventCount = static_cast<std::size_t>(Event::count_);
inline constexpr std::size_t kModeCount = 8;

const char* to_string(Mode m);
const char* to_string(Event e);

// What the hardware may do in a mode (ros2_control's per-state permissions).
struct ModePolicy {
  Mode mode;
  bool pump;          // ring electrode may be driven
  bool forcers;       // x/y forcers may be driven (AGC, quadrature, pattern control)
  bool enable_line;   // hardware excitation-enable output
  bool output_valid;  // gyro angle output may be flagged valid
  bool identify;      // samples feed the identification windows
};

// Indexed by Mode. Drives are at zero in power_up, free_decay, fault and safe;
// the enable line is low in power_up and safe (a second, independent path).
inline constexpr std::array<ModePolicy, kModeCount> kModePolicies{{
    // mode              pump   forcers enable valid  identify
    {Mode::power_up, false, false, false, false, false},
    {Mode::ring_up, true, true, true, false, false},
    {Mode::lock, true, true, true, false, false},
    {Mode::operate, true, true, true, true, false},
    {Mode::free_decay, false, false, true, true, true},
    {Mode::recover, true, true, true, true, false},
    {Mode::fault, false, false, true, false, false},
    {Mode::safe, false, false, false, false, false},
}};

constexpr const ModePolicy& policy(Mode m) { return kModePolicies[static_cast<std::size_t>(m)]; }

struct Transition {
  Mode from;
  Event event;
  Mode to;
};

// The transition table. Any (mode, event) pair that is not listed is ignored
// (and counted). Faults that mean the drive electronics themselves are
// suspect (dac_fault, external) go to safe directly; see ModeMachine::handle.
inline constexpr std::array kTransitions{
    Transition{Mode::power_up, Event::self_test_passed, Mode::ring_up},
    Transition{Mode::ring_up, Event::amplitude_reached, Mode::lock},
    Transition{Mode::lock, Event::loops_settled, Mode::operate},
    Transition{Mode::operate, Event::window_open, Mode::free_decay},
    Transition{Mode::free_decay, Event::window_close, Mode::recover},
    Transition{Mode::recover, Event::reacquired, Mode::operate},
    Transition{Mode::power_up, Event::fault_detected, Mode::safe},
    Transition{Mode::ring_up, Event::fault_detected, Mode::fault},
    Transition{Mode::lock, Event::fault_detected, Mode::fault},
    Transition{Mode::operate, Event::fault_detected, Mode::fault},
    Transition{Mode::free_decay, Event::fault_detected, Mode::fault},
    Transition{Mode::recover, Event::fault_detected, Mode::fault},
    Transition{Mode::fault, Event::fault_cleared, Mode::ring_up},
    Transition{Mode::fault, Event::retries_exhausted, Mode::safe},
    Transition{Mode::power_up, Event::command_safe, Mode::safe},
    Transition{Mode::ring_up, Event::command_safe, Mode::safe},
    Transition{Mode::lock, Event::command_safe, Mode::safe},
    Transition{Mode::operate, Event::command_safe, Mode::safe},
    Transition{Mode::free_decay, Event::command_safe, Mode::safe},
    Transition{Mode::recover, Event::command_safe, Mode::safe},
    Transition{Mode::fault, Event::command_safe, Mode::safe},
    Transition{Mode::safe, Event::command_restart, Mode::power_up},
};

// Looks up (from, event); returns false when the pair is not in the table.
constexpr bool lookup_transition(Mode from, Event event, Mode& to) {
  for (const auto& t : kTransitions) {
    if (t.from == from && t.event == event) {
      to = t.to;
      return true;
    }
  }
  return false;
}

// No (mode, event) pair may appear twice: the table must be a function.
constexpr bool transitions_unique() {
  for (std::size_t i = 0; i < kTransitions.size(); ++i) {
    for (std::size_t j = i + 1; j < kTransitions.size(); ++j) {
      if (kTransitions[i].from == kTransitions[j].from &&
          kTransitions[i].event == kTransitions[j].event) {
        return false;
      }
    }
  }
  return true;
}
static_assert(transitions_unique(), "mode transition table has a duplicate (mode, event)");

// Faults that send the machine to safe from any mode: the drive path itself
// is suspect, so retrying with drives on is not allowed.
inline constexpr uint16_t kSevereFaults = fault_bit(Fault::dac_fault) | fault_bit(Fault::external);

// The mode state machine. Task context; never blocks, never allocates.
class ModeMachine {
 public:
  // `max_retries`: recoveries from fault allowed in a row before safe.
  explicit ModeMachine(uint8_t max_retries = 3) : max_retries_(max_retries) {}

  Mode mode() const { return mode_; }
  const ModePolicy& permissions() const { return policy(mode_); }
  // Fault bits latched since the last recovery (Fault bit set).
  uint16_t faults() const { return faults_; }
  uint8_t retries() const { return retries_; }
  uint32_t ignored_events() const { return ignored_; }
  uint32_t transitions() const { return transitions_; }

  // Applies an event. `fault_bits` is used with fault_detected. Returns true
  // when the mode changed.
  bool handle(Event e, uint16_t fault_bits = 0);

 private:
  bool go(Mode to);

  Mode mode_ = Mode::power_up;
  uint16_t faults_ = 0;
  uint8_t max_retries_;
  uint8_t retries_ = 0;
  uint32_t ignored_ = 0;
  uint32_t transitions_ = 0;
};

}  // namespace hrg::fw
