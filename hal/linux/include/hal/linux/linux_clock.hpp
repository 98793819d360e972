// SPDX-License-Identifier: MIT
#pragma once

#include "hal/clock.hpp"

namespace hrg::hal::linux_board {

// CLOCK_MONOTONIC in nanoseconds; sleeps with clock_nanosleep(TIMER_ABSTIME), so
// a periodic loop that adds its period to the previous deadline does not drift.
class LinuxClock final : public MonotonicClock {
 public:
  uint64_t now_ns() const override;
  // ok after sleeping until t_ns; timeout (without sleeping) when t_ns has
  // already passed: the caller counts a missed deadline.
  Status sleep_until_ns(uint64_t t_ns) override;
};

}  // namespace hrg::hal::linux_board
