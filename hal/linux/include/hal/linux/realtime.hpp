// SPDX-License-Identifier: MIT
#pragma once

namespace hrg::hal::linux_board {

// What real-time setup obtained. Every item is attempted; a refusal (no
// CAP_SYS_NICE, RLIMIT_MEMLOCK too low, ...) is reported here, never fatal: the
// executive still runs, with the misses it then has counted.
struct RealtimeReport {
  bool fifo = false;           // SCHED_FIFO at the requested priority
  int priority = 0;            // priority obtained (0 when not FIFO)
  int fifo_errno = 0;          // why SCHED_FIFO was refused
  bool memory_locked = false;  // mlockall(MCL_CURRENT | MCL_FUTURE)
  int mlock_errno = 0;
  bool cpu_pinned = false;  // affinity to `cpu` (when cpu >= 0)
  int affinity_errno = 0;
};

struct RealtimeRequest {
  int priority = 80;        // SCHED_FIFO priority, 1..99
  bool lock_memory = true;  // mlockall so page faults do not stall a frame
  int cpu = -1;             // pin the calling thread to this CPU (-1: leave)
  // Bytes of stack touched after locking so the executive never faults on it.
  unsigned prefault_stack_bytes = 64 * 1024;
};

// Applies the request to the calling thread and the process.
RealtimeReport setup_realtime(const RealtimeRequest& request);

// One line describing the report, e.g. "SCHED_FIFO 80, memory locked" or
// "SCHED_OTHER (SCHED_FIFO refused: Operation not permitted), ...". Writes into
// `buf` (always NUL-terminated) and returns it.
const char* describe(const RealtimeReport& report, char* buf, unsigned size);

}  // namespace hrg::hal::linux_board
