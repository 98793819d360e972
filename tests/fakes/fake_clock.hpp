// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

#include "hal/clock.hpp"

namespace hrg::fakes {

// A monotonic clock the test moves by hand. Back door: set_now_ns/advance_ns.
// As a pacing clock it behaves like real time: sleep_until_ns jumps to the
// deadline, or returns timeout when the deadline has already passed; with
// lockstep() it returns at once without moving (the simulated target's clock).
class FakeClock final : public hal::MonotonicClock {
 public:
  uint64_t now_ns() const override { return now_ns_; }
  hal::Status sleep_until_ns(uint64_t t_ns) override {
    ++sleeps_;
    if (t_ns < now_ns_) return hal::Status::timeout;
    if (!lockstep_) now_ns_ = t_ns;
    return hal::Status::ok;
  }

  void set_now_ns(uint64_t t_ns) { now_ns_ = t_ns; }
  void advance_ns(uint64_t dt_ns) { now_ns_ += dt_ns; }
  void set_lockstep(bool on) { lockstep_ = on; }
  uint32_t sleeps() const { return sleeps_; }

 private:
  uint64_t now_ns_ = 0;
  uint32_t sleeps_ = 0;
  bool lockstep_ = false;
};

}  // namespace hrg::fakes
