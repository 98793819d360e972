// SPDX-License-Identifier: MIT
#include "firmware/executive.hpp"

#include <array>
#include <cstdint>

#include "fakes/fake_clock.hpp"

#include "support/cpputest.hpp"

using hrg::fakes::FakeClock;
using hrg::fw::Executive;
using hrg::fw::Pacing;
using hrg::fw::Task;

namespace {

// Each task logs its index and consumes `cost_ns[i]` on the timer clock.
struct Ctx {
  FakeClock* timer = nullptr;
  std::array<uint64_t, 4> cost_ns{};
  std::array<uint8_t, 64> log{};
  uint32_t n = 0;
  void ran(uint8_t i) {
    if (n < log.size()) log[n++] = i;
    timer->advance_ns(cost_ns[i]);
  }
};

void t0(Ctx& c) { c.ran(0); }
void t1(Ctx& c) { c.ran(1); }
void t2(Ctx& c) { c.ran(2); }
void t3(Ctx& c) { c.ran(3); }

constexpr uint32_t kBase = 1'000;
constexpr std::array<Task<Ctx>, 4> kTable{{
    {"adc_chain", &t0, 1'000, 300'000},
    {"monitor", &t1, 1'000, 50'000},
    {"scheduler", &t2, 100, 50'000},
    {"solve", &t3, 10, 200'000},
}};
static_assert(hrg::fw::all_rates_divide(kTable, kBase));
static_assert(hrg::fw::total_budget_ns(kTable) <= 1'000'000ull);

constexpr std::array<Task<Ctx>, 1> kOddRate{{{"bad", &t0, 300, 1}}};
static_assert(!hrg::fw::all_rates_divide(kOddRate, kBase), "300 Hz does not divide 1 kHz");
constexpr std::array<Task<Ctx>, 1> kZeroRate{{{"bad", &t0, 0, 1}}};
static_assert(!hrg::fw::all_rates_divide(kZeroRate, kBase));
constexpr std::array<Task<Ctx>, 1> kTooFast{{{"bad", &t0, 2'000, 1}}};
static_assert(!hrg::fw::all_rates_divide(kTooFast, kBase));

}  // namespace

TEST_GROUP(Executive) {
  FakeClock clock;
  Ctx ctx;
  void setup() override { ctx.timer = &clock; }
};

TEST(Executive, RunsEachTaskAtItsRateOverOneSecond) {
  Executive<Ctx, 4> ex(kTable, kBase, clock, clock, Pacing::real_time);
  for (int i = 0; i < 1000; ++i)
    ex.run_frame(ctx);
  LONGS_EQUAL(1000, ex.task_stats()[0].runs);
  LONGS_EQUAL(1000, ex.task_stats()[1].runs);
  LONGS_EQUAL(100, ex.task_stats()[2].runs);
  LONGS_EQUAL(10, ex.task_stats()[3].runs);
  LONGS_EQUAL(1000, ex.frame_stats().frames);
  // Real-time pacing: 1000 frames of 1 ms end at t = 999 ms (frame 0 at t = 0).
  LONGS_EQUAL(999'000'000, clock.now_ns());
}

TEST(Executive, RunsDueTasksInTableOrder) {
  Executive<Ctx, 4> ex(kTable, kBase, clock, clock, Pacing::real_time);
  ex.run_frame(ctx);  // frame 0: all four are due
  ex.run_frame(ctx);  // frame 1: only the 1 kHz pair
  LONGS_EQUAL(6, ctx.n);
  const uint8_t expected[] = {0, 1, 2, 3, 0, 1};
  for (uint32_t i = 0; i < 6; ++i)
    LONGS_EQUAL(expected[i], ctx.log[i]);
}

TEST(Executive, RecordsMinAndMaxExecutionTime) {
  Executive<Ctx, 4> ex(kTable, kBase, clock, clock, Pacing::real_time);
  ctx.cost_ns[0] = 100'000;
  ex.run_frame(ctx);
  ctx.cost_ns[0] = 250'000;
  ex.run_frame(ctx);
  ctx.cost_ns[0] = 10'000;
  ex.run_frame(ctx);
  LONGS_EQUAL(10'000, ex.task_stats()[0].min_ns);
  LONGS_EQUAL(250'000, ex.task_stats()[0].max_ns);
  LONGS_EQUAL(360'000, ex.task_stats()[0].total_ns);
  LONGS_EQUAL(0, ex.task_stats()[0].overruns);
}

TEST(Executive, CountsAnOverrunWhenATaskExceedsItsBudgetAndSlipsForTheTasksAfterIt) {
  Executive<Ctx, 4> ex(kTable, kBase, clock, clock, Pacing::real_time);
  // GIVEN the first task takes 450 us against a 300 us budget
  ctx.cost_ns[0] = 450'000;
  // WHEN frame 0 runs (all tasks due)
  ex.run_frame(ctx);
  // THEN task 0 overran, and every later task started after its slot
  LONGS_EQUAL(1, ex.task_stats()[0].overruns);
  LONGS_EQUAL(0, ex.task_stats()[0].slips);
  LONGS_EQUAL(0, ex.task_stats()[1].overruns);
  LONGS_EQUAL(1, ex.task_stats()[1].slips);
  LONGS_EQUAL(1, ex.task_stats()[2].slips);
  LONGS_EQUAL(1, ex.task_stats()[3].slips);
  LONGS_EQUAL(1, ex.recent_overrun_frames());
}

TEST(Executive, ATaskWithinBudgetDoesNotMakeLaterTasksSlip) {
  Executive<Ctx, 4> ex(kTable, kBase, clock, clock, Pacing::real_time);
  ctx.cost_ns = {300'000, 50'000, 50'000, 200'000};  // exactly on budget
  ex.run_frame(ctx);
  for (const auto& s : ex.task_stats()) {
    LONGS_EQUAL(0, s.slips);
    LONGS_EQUAL(0, s.overruns);
  }
  LONGS_EQUAL(600'000, ex.frame_stats().max_frame_ns);
}

TEST(Executive, CountsMissedFramesWhenAFrameRunsPastTheNextDeadlines) {
  Executive<Ctx, 4> ex(kTable, kBase, clock, clock, Pacing::real_time);
  ex.run_frame(ctx);  // frame 0 at t = 0
  // GIVEN a frame that takes 3.5 ms (the task stalls)
  ctx.cost_ns[0] = 3'500'000;
  ex.run_frame(ctx);  // starts at 1 ms, ends at 4.5 ms
  ctx.cost_ns[0] = 0;
  // WHEN the next frame is paced
  ex.run_frame(ctx);
  // THEN its deadline (2 ms) was missed, the 2 ms and 3 ms frames are counted
  // as missed, and it runs at once without a catch-up burst
  LONGS_EQUAL(1, ex.frame_stats().deadline_misses);
  LONGS_EQUAL(2, ex.frame_stats().missed_frames);
  LONGS_EQUAL(4'500'000, clock.now_ns());
  // AND the schedule goes on from 5 ms
  ex.run_frame(ctx);
  LONGS_EQUAL(5'000'000, clock.now_ns());
  LONGS_EQUAL(1, ex.frame_stats().deadline_misses);
}

TEST(Executive, LateByLessThanAPeriodIsADeadlineMissButNoMissedFrame) {
  Executive<Ctx, 4> ex(kTable, kBase, clock, clock, Pacing::real_time);
  ex.run_frame(ctx);
  ctx.cost_ns[0] = 1'400'000;
  ex.run_frame(ctx);  // 1 ms .. 2.4 ms
  ctx.cost_ns[0] = 0;
  ex.run_frame(ctx);
  LONGS_EQUAL(1, ex.frame_stats().deadline_misses);
  LONGS_EQUAL(0, ex.frame_stats().missed_frames);
}

TEST(Executive, LockstepPacingNeverWaitsAndCountsNoMisses) {
  // The pacing clock is the simulated one: it moves only when the ADC task
  // produces a block (here, the test moves it by one period per frame).
  FakeClock sim;
  sim.set_lockstep(true);
  Executive<Ctx, 4> ex(kTable, kBase, sim, clock, Pacing::lockstep);
  ctx.cost_ns[0] = 5'000'000;  // host time does not matter in lockstep
  for (int i = 0; i < 20; ++i) {
    ex.run_frame(ctx);
    sim.advance_ns(1'000'000);
  }
  LONGS_EQUAL(20, sim.sleeps());
  LONGS_EQUAL(0, ex.frame_stats().deadline_misses);
  LONGS_EQUAL(0, ex.frame_stats().missed_frames);
  LONGS_EQUAL(20, ex.task_stats()[0].overruns);
}

TEST(Executive, RecentOverrunFramesForgetsFramesOlderThan64) {
  Executive<Ctx, 4> ex(kTable, kBase, clock, clock, Pacing::real_time);
  ctx.cost_ns[1] = 60'000;  // monitor over its 50 us budget every frame
  for (int i = 0; i < 10; ++i)
    ex.run_frame(ctx);
  LONGS_EQUAL(10, ex.recent_overrun_frames());
  ctx.cost_ns[1] = 0;
  for (int i = 0; i < 64; ++i)
    ex.run_frame(ctx);
  LONGS_EQUAL(0, ex.recent_overrun_frames());
  LONGS_EQUAL(10, ex.task_stats()[1].overruns);
}
