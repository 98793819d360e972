// SPDX-License-Identifier: MIT
#include "hal/linux/linux_clock.hpp"

#include <time.h>

#include <cerrno>

namespace hrg::hal::linux_board {

uint64_t LinuxClock::now_ns() const {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1'000'000'000ull + static_cast<uint64_t>(ts.tv_nsec);
}

Status LinuxClock::sleep_until_ns(uint64_t t_ns) {
  if (now_ns() >= t_ns) return Status::timeout;
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / 1'000'000'000ull);
  ts.tv_nsec = static_cast<long>(t_ns % 1'000'000'000ull);
  int r = 0;
  // EINTR: a signal interrupted the sleep; the deadline is absolute, so resume.
  while ((r = clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr)) == EINTR) {
  }
  return r == 0 ? Status::ok : Status::io_error;
}

}  // namespace hrg::hal::linux_board
