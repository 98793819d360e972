// SPDX-License-Identifier: MIT
#include "hal/linux/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace hrg::hal::linux_board {

namespace {

// Touches stack pages once so they are resident (and locked) before the loop.
__attribute__((noinline)) void prefault_stack(unsigned bytes) {
  constexpr unsigned kChunk = 4096;
  unsigned char page[kChunk];
  std::memset(page, 0, sizeof page);
  asm volatile("" : : "r"(page) : "memory");  // keep the writes
  if (bytes > kChunk) prefault_stack(bytes - kChunk);
}

}  // namespace

RealtimeReport setup_realtime(const RealtimeRequest& request) {
  RealtimeReport r;
  if (request.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      r.memory_locked = true;
      prefault_stack(request.prefault_stack_bytes);
    } else {
      r.mlock_errno = errno;
    }
  }
  if (request.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(request.cpu), &set);
    const int e = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    r.cpu_pinned = e == 0;
    r.affinity_errno = e;
  }
  sched_param sp{};
  sp.sched_priority = request.priority;
  const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (e == 0) {
    r.fifo = true;
    r.priority = request.priority;
  } else {
    r.fifo_errno = e;
  }
  return r;
}

const char* describe(const RealtimeReport& r, char* buf, unsigned size) {
  if (size == 0) return buf;
  char fifo[96];
  char mem[96];
  if (r.fifo) {
    std::snprintf(fifo, sizeof fifo, "SCHED_FIFO %d", r.priority);
  } else {
    std::snprintf(fifo, sizeof fifo, "SCHED_OTHER (SCHED_FIFO refused: %s)",
                  std::strerror(r.fifo_errno));
  }
  if (r.memory_locked) {
    std::snprintf(mem, sizeof mem, "memory locked");
  } else if (r.mlock_errno != 0) {
    std::snprintf(mem, sizeof mem, "memory not locked (%s)", std::strerror(r.mlock_errno));
  } else {
    std::snprintf(mem, sizeof mem, "memory not locked (not requested)");
  }
  std::snprintf(buf, size, "%s, %s", fifo, mem);
  return buf;
}

}  // namespace hrg::hal::linux_board
