// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

#include "hal/status.hpp"

namespace hrg::hal {

// Monotonic time in nanoseconds. In lockstep simulation it is the simulated
// time and advances only when the ADC produces a block.
class MonotonicClock : NonCopyable {
 public:
  virtual ~MonotonicClock() = default;
  virtual uint64_t now_ns() const = 0;
  // Sleeps until the absolute time (real time) or returns at once (lockstep).
  // Returns timeout when the time had already passed (a missed deadline).
  virtual Status sleep_until_ns(uint64_t t_ns) = 0;
};

}  // namespace hrg::hal
