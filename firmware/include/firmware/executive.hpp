// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/clock.hpp"

namespace hrg::fw {

// One row of the executive's task table. `run` is a plain function taking the
// firmware context, so a table can be a constexpr array (no captures, no heap).
template <class Ctx>
struct Task {
  const char* name;
  void (*run)(Ctx&);
  uint32_t rate_hz;    // must divide the base rate
  uint32_t budget_ns;  // execution time allowed per run; longer is an overrun
};

// True when every task's rate is non-zero and divides the base rate, so each
// task runs on a whole number of base frames ("no arbitrary rates").
template <class Ctx, std::size_t N>
constexpr bool all_rates_divide(const std::array<Task<Ctx>, N>& tasks, uint32_t base_rate_hz) {
  for (const auto& t : tasks) {
    if (t.rate_hz == 0 || t.rate_hz > base_rate_hz || base_rate_hz % t.rate_hz != 0) return false;
  }
  return true;
}

// Sum of the budgets of the tasks that run in a frame where every task is due:
// the worst frame must fit in the base period.
template <class Ctx, std::size_t N>
constexpr uint64_t total_budget_ns(const std::array<Task<Ctx>, N>& tasks) {
  uint64_t sum = 0;
  for (const auto& t : tasks)
    sum += t.budget_ns;
  return sum;
}

// Per-task counters (ArduPilot's PerfInfo). Times are from the executive's timer
// clock, in nanoseconds, saturating at UINT32_MAX.
struct TaskStats {
  uint32_t min_ns = UINT32_MAX;
  uint32_t max_ns = 0;
  uint64_t total_ns = 0;
  uint64_t runs = 0;
  uint32_t overruns = 0;  // runs that took longer than the budget
  uint32_t slips = 0;     // runs that started after their slot in the frame (earlier tasks overran)
};

struct FrameStats {
  uint64_t frames = 0;           // base frames executed
  uint32_t missed_frames = 0;    // whole base periods skipped (never caught up silently)
  uint32_t deadline_misses = 0;  // frames whose start deadline had already passed
  uint32_t max_frame_ns = 0;     // longest frame (all tasks), timer clock
};

// How frames are paced. The code is the same in both: the executive asks the
// pacing clock to sleep until the frame's absolute start time. In lockstep the
// simulated clock returns at once (time advances only when the ADC produces a
// block); in real time it sleeps (clock_nanosleep with TIMER_ABSTIME on Linux).
enum class Pacing : uint8_t { lockstep = 0, real_time = 1 };

// Cyclic executive: one base frame per ADC block. Tasks run in table order, a
// task of rate r on every (base/r)-th frame. Nothing is allocated: the table is
// held by reference and the statistics live in a std::array sized from it.
// Calling context: a single thread (or the main loop on bare metal).
template <class Ctx, std::size_t N>
class Executive {
 public:
  static constexpr std::size_t kTaskCount = N;

  // `pace` provides the frame deadlines; `timer` measures execution time (the
  // same clock in real time; a host clock in lockstep, where simulated time
  // does not move while a task runs).
  Executive(const std::array<Task<Ctx>, N>& tasks, uint32_t base_rate_hz, hal::MonotonicClock& pace,
            hal::MonotonicClock& timer, Pacing pacing)
      : tasks_(tasks),
        base_rate_hz_(base_rate_hz),
        period_ns_(1'000'000'000ull / base_rate_hz),
        pace_(pace),
        timer_(timer),
        pacing_(pacing) {
    for (std::size_t i = 0; i < N; ++i)
      divider_[i] = base_rate_hz / tasks[i].rate_hz;
  }

  // Sets the start time of frame 0 (pacing clock, ns).
  void start(uint64_t t0_ns) {
    next_deadline_ns_ = t0_ns;
    started_ = true;
  }

  // Runs one base frame: waits for its deadline, then every due task in order.
  void run_frame(Ctx& ctx) {
    if (!started_) start(pace_.now_ns());
    pace_frame();
    uint64_t frame_start = 0;
    bool first = true;
    uint64_t slot_ns = 0;  // where the next task's slot begins, relative to frame start
    bool any_overrun = false;
    // One timer read per task boundary: a task starts when the previous one
    // ended (the bookkeeping between them is a few ns), which halves the
    // clock reads of a lockstep run.
    uint64_t t_last = 0;
    for (std::size_t i = 0; i < N; ++i) {
      if (tick_ % divider_[i] != 0) continue;
      const uint64_t t_start = first ? timer_.now_ns() : t_last;
      if (first) {
        // The frame starts with its first task: that task cannot slip.
        frame_start = t_start;
        first = false;
      }
      tasks_[i].run(ctx);
      const uint64_t t_end = timer_.now_ns();
      t_last = t_end;
      auto& s = stats_[i];
      const uint32_t dt = clamp_u32(t_end - t_start);
      if (dt < s.min_ns) s.min_ns = dt;
      if (dt > s.max_ns) s.max_ns = dt;
      s.total_ns += dt;
      ++s.runs;
      if (dt > tasks_[i].budget_ns) {
        ++s.overruns;
        any_overrun = true;
      }
      if (t_start - frame_start > slot_ns) ++s.slips;
      slot_ns += tasks_[i].budget_ns;
    }
    const uint32_t frame_ns = first ? 0 : clamp_u32(t_last - frame_start);
    if (frame_ns > frame_.max_frame_ns) frame_.max_frame_ns = frame_ns;
    overrun_history_ = (overrun_history_ << 1) | (any_overrun ? 1u : 0u);
    ++frame_.frames;
    ++tick_;
  }

  const std::array<TaskStats, N>& task_stats() const { return stats_; }
  const FrameStats& frame_stats() const { return frame_; }
  const Task<Ctx>& task(std::size_t i) const { return tasks_[i]; }
  uint32_t base_rate_hz() const { return base_rate_hz_; }
  uint64_t period_ns() const { return period_ns_; }
  uint64_t tick() const { return tick_; }
  Pacing pacing() const { return pacing_; }
  // Frames with at least one overrun among the last 64 frames (overrun storm detector input).
  uint32_t recent_overrun_frames() const { return popcount64(overrun_history_); }

  void reset_stats() {
    stats_ = {};
    frame_ = {};
    overrun_history_ = 0;
  }

 private:
  static uint32_t clamp_u32(uint64_t v) {
    return v > UINT32_MAX ? UINT32_MAX : static_cast<uint32_t>(v);
  }
  static uint32_t popcount64(uint64_t v) {
    uint32_t n = 0;
    for (; v != 0; v &= v - 1)
      ++n;
    return n;
  }

  // Sleeps until this frame's deadline. When the deadline has passed by one or
  // more whole periods, those frames are counted as missed and the schedule
  // moves on (modm's periodic timer), instead of running a burst to catch up.
  void pace_frame() {
    const hal::Status st = pace_.sleep_until_ns(next_deadline_ns_);
    const uint64_t now = pace_.now_ns();
    // Frame 0's deadline is the start time itself: reading the clock has
    // already passed it, which is no miss.
    const bool late = st == hal::Status::timeout || now > next_deadline_ns_ + period_ns_;
    if (late && frame_.frames > 0) {
      ++frame_.deadline_misses;
      if (now > next_deadline_ns_) {
        const uint64_t late_periods = (now - next_deadline_ns_) / period_ns_;
        frame_.missed_frames += clamp_u32(late_periods);
        next_deadline_ns_ += late_periods * period_ns_;
      }
    }
    next_deadline_ns_ += period_ns_;
  }

  const std::array<Task<Ctx>, N>& tasks_;
  uint32_t base_rate_hz_;
  uint64_t period_ns_;
  hal::MonotonicClock& pace_;
  hal::MonotonicClock& timer_;
  Pacing pacing_;
  std::array<uint32_t, N> divider_{};
  std::array<TaskStats, N> stats_{};
  FrameStats frame_{};
  uint64_t tick_ = 0;
  uint64_t next_deadline_ns_ = 0;
  uint64_t overrun_history_ = 0;
  bool started_ = false;
};

}  // namespace hrg::fw
