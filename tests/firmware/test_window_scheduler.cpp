// SPDX-License-Identifier: MIT
#include "firmware/window_scheduler.hpp"

#include <cmath>
#include <cstdint>
#include <algorithm>
#include <array>
#include <numbers>
#include <vector>

#include "support/window_loop.hpp"

#include "support/cpputest.hpp"

using hrg::fw::EstimatorHealth;
using hrg::fw::Mode;
using hrg::fw::WindowConfig;
using hrg::fw::WindowDecision;
using hrg::fw::WindowScheduler;

namespace {
constexpr double kPi = std::numbers::pi;

WindowConfig small_config() {
  WindowConfig c;
  c.length_frames = 10;
  c.period_frames = 50;
  c.max_wait_frames = 400;
  c.bins = 8;
  c.windows_per_bin = 2;
  return c;
}

using Loop = hrg::test::WindowLoop;
}  // namespace

TEST_GROUP(WindowScheduler){};

TEST(WindowScheduler, BinsFollowFourThetaAndRepeatEveryQuarterTurn) {
  WindowScheduler s(small_config());  // 8 bins of 45 deg in 4 theta
  LONGS_EQUAL(0, s.bin_of(0.0));
  LONGS_EQUAL(1, s.bin_of(kPi / 16 + 1e-6));  // 4 theta just above 45 deg
  LONGS_EQUAL(7, s.bin_of(-1e-6));            // just below 0 wraps to the last bin
  LONGS_EQUAL(s.bin_of(0.3), s.bin_of(0.3 + kPi / 2));
  DOUBLES_EQUAL(kPi / 32, s.bin_centre_near(0, 0.0), 1e-12);
  DOUBLES_EQUAL(kPi / 32 + kPi / 2, s.bin_centre_near(0, kPi / 2), 1e-12);
}

TEST(WindowScheduler, WindowsHaveTheConfiguredLengthAndPeriod) {
  Loop l(small_config());
  // Turning base, theta sweeping fast: every bin is under-covered in turn.
  uint32_t first_open = 0, second_open = 0, closes = 0, off = 0;
  for (uint32_t f = 0; f < 200; ++f) {
    const double theta = 0.005 * f;  // a 4 theta bin every 39 frames
    const auto d = l.frame(theta, 2.0);
    if (d.open && l.opened == 1) first_open = f;
    if (d.open && l.opened == 2) second_open = f;
    if (d.close) ++closes;
    if (l.mode == Mode::free_decay) ++off;
  }
  LONGS_EQUAL(0, first_open);    // the first window opens at once
  LONGS_EQUAL(50, second_open);  // then one per period
  LONGS_EQUAL(4, closes);        // at 0, 50, 100, 150
  LONGS_EQUAL(40, off);
  DOUBLES_EQUAL(40.0 / 200.0, l.s.excitation_off_fraction(), 1e-12);
}

TEST(WindowScheduler, PrefersUnderCoveredBinsAndWaitsInACoveredOne) {
  auto c = small_config();
  c.max_wait_frames = 10'000;
  Loop l(c);
  // GIVEN one window already taken in bin 0
  for (int f = 0; f < 11; ++f)
    l.frame(0.01, 2.0);
  LONGS_EQUAL(1, l.s.bin_count(0));
  // WHEN theta stays in bin 0 on a moving base past the period
  for (int f = 0; f < 300; ++f)
    l.frame(0.01, 2.0);
  // THEN no second window is taken there
  LONGS_EQUAL(1, l.opened);
  // AND as soon as theta enters bin 3 one opens
  const auto d = l.frame(3.5 * kPi / 16, 2.0);
  CHECK(d.open);
}

TEST(WindowScheduler, OpensAnywayAfterTheLongestWaitOnAMovingBase) {
  Loop l(small_config());  // max wait 400
  for (int f = 0; f < 11; ++f)
    l.frame(0.01, 2.0);
  uint32_t f = 11;
  while (l.opened < 2 && f < 1000) {
    l.frame(0.01, 2.0);
    ++f;
  }
  LONGS_EQUAL(2, l.opened);
  LONGS_EQUAL(400, f - 1);  // 400 frames after the first window opened at frame 0
}

TEST(WindowScheduler, OnAStaticBaseItCommandsThePatternToTheLeastCoveredBin) {
  Loop l(small_config());
  for (int f = 0; f < 11; ++f)
    l.frame(0.01, 0.0);  // window in bin 0
  WindowDecision d;
  for (int f = 0; f < 60; ++f)
    d = l.frame(0.01, 0.0);
  CHECK(d.pattern_command);
  // bin 7 (4 theta = 337.5 deg, theta = -5.6 deg) is the nearest empty bin to
  // theta = 0.6 deg; bin 1 (theta = 16.9 deg) is farther
  DOUBLES_EQUAL(-kPi / 32, d.pattern_target_rad, 1e-12);
  // WHEN the pattern gets there a window opens
  d = l.frame(d.pattern_target_rad, 0.0);
  CHECK(d.open);
  LONGS_EQUAL(2, l.opened);
}

TEST(WindowScheduler, StopsWhenTheEstimatorReportsGoodConditionAndCoverage) {
  Loop l(small_config());
  EstimatorHealth good{true, 50.0, 1.0};
  EstimatorHealth poor{true, 1e6, 1.0};
  for (int f = 0; f < 100; ++f)
    l.frame(0.05 * f, 2.0, poor);
  const uint32_t before = l.opened;
  CHECK(before >= 2);
  CHECK_FALSE(l.s.campaign_done());
  for (int f = 0; f < 1000; ++f)
    l.frame(0.05 * f, 2.0, good);
  CHECK(l.s.campaign_done());
  LONGS_EQUAL(before, l.opened);  // a window running at the time may finish, none opens after
}

TEST(WindowScheduler, AWindowAbortedByAFaultDoesNotCount) {
  WindowScheduler s(small_config());
  auto d = s.step(Mode::operate, 0.01, 2.0, {});
  CHECK(d.open);
  s.step(Mode::free_decay, 0.01, 2.0, {});
  s.step(Mode::fault, 0.01, 2.0, {});
  CHECK_FALSE(s.in_window());
  LONGS_EQUAL(0, s.bin_count(0));
  LONGS_EQUAL(0, s.windows());
}

TEST(WindowScheduler, FillsAllBinsEvenlyOnASweep) {
  auto c = small_config();
  c.windows_per_bin = 3;
  c.condition_good = 0;  // the estimator never says good: the cap ends the campaign
  Loop l(c);
  for (int f = 0; f < 40'000; ++f)
    l.frame(1e-3 * f, 1.0);
  CHECK(l.s.campaign_done());
  uint32_t lo = 1000, hi = 0;
  for (uint32_t b = 0; b < 8; ++b) {
    lo = l.s.bin_count(b) < lo ? l.s.bin_count(b) : lo;
    hi = l.s.bin_count(b) > hi ? l.s.bin_count(b) : hi;
  }
  LONGS_EQUAL(3, lo);
  CHECK(hi - lo <= 1);
}

TEST(WindowScheduler, TheEstimatorsWordCountsOnlyOnceEveryBinHasItsMinimum) {
  auto c = small_config();
  c.min_windows_per_bin = 1;
  c.windows_per_bin = 100;
  Loop l(c);
  EstimatorHealth good{true, 50.0, 1.0};
  // GIVEN a good estimator from the start, theta sweeping
  int f = 0;
  for (; f < 100'000 && !l.s.campaign_done(); ++f)
    l.frame(1e-3 * f, 1.0, good);
  // THEN the campaign ends exactly when the last bin gets its first window
  CHECK(l.s.campaign_done());
  for (uint32_t b = 0; b < 8; ++b)
    CHECK(l.s.bin_count(b) >= 1);
  LONGS_EQUAL(8, l.s.windows());
}

TEST(WindowScheduler, OnAStaticBaseThePatternWalksToTheNearestEmptyBin) {
  Loop l(small_config());  // 8 bins of 11.25 deg of theta
  // GIVEN windows taken in bins 0 and 1 (theta 0.01 and 0.25)
  for (int f = 0; f < 11; ++f)
    l.frame(0.01, 0.0);
  for (int f = 0; f < 60; ++f)
    l.frame(0.25, 0.0);
  LONGS_EQUAL(1, l.s.bin_count(0));
  LONGS_EQUAL(1, l.s.bin_count(1));
  // WHEN the pattern sits in bin 1 again after the period
  WindowDecision d;
  for (int f = 0; f < 60; ++f)
    d = l.frame(0.25, 0.0);
  // THEN it is sent to bin 2 (next to it), not back across the circle to bin 7
  CHECK(d.pattern_command);
  LONGS_EQUAL(2, l.s.bin_of(d.pattern_target_rad));
  DOUBLES_EQUAL(2.5 * kPi / 16, d.pattern_target_rad, 1e-12);
}

TEST(WindowScheduler, AfterTheCampaignCheckWindowsRunAtTheirPeriodAndOnceTheBaseIsStill) {
  WindowConfig c = small_config();
  c.check_period_frames = 500;
  Loop l(c);
  EstimatorHealth good{true, 50.0, 1.0};
  for (int f = 0; f < 200; ++f)  // turning: the campaign ends on the estimator's word
    l.frame(0.05 * f, 2.0, good);
  CHECK(l.s.campaign_done());
  // Still turning: one check window per check period (1000 frames -> 2).
  uint32_t before = l.opened;
  for (int f = 0; f < 1000; ++f)
    l.frame(10.0 + 0.05 * f, 2.0, good);
  LONGS_EQUAL(before + 2, l.opened);
  // The base stops: a check window once it has been still for a window
  // period (50 frames), long before the next check period.
  before = l.opened;
  int first = -1;
  for (int f = 0; f < 400 && first < 0; ++f) {
    if (l.frame(1.0, 0.0, good).open) first = f;
  }
  LONGS_EQUAL(49, first);  // the 50th still frame
  // ... and only once: the next one waits for the period again.
  for (int f = 0; f < 400; ++f)
    l.frame(1.0, 0.0, good);
  LONGS_EQUAL(before + 1, l.opened);
  CHECK(l.s.campaign_done());
}

TEST(WindowScheduler, AModelNewlyInForceIsCheckedAfterTheSettlingDelayThenAtThePeriod) {
  // GIVEN a campaign of a window per bin, checks every 5000 frames, the
  // first one of a model 100 frames after it
  WindowConfig c = small_config();
  c.min_windows_per_bin = 1;
  c.check_period_frames = 5000;
  c.first_check_delay_frames = 100;
  Loop l(c);
  EstimatorHealth good{true, 50.0, 1.0};
  int f = 0;
  for (; !l.s.campaign_done(); ++f)  // turning: the campaign ends on the estimator's word
    l.frame(0.05 * f, 2.0, good);
  // THEN the campaign's model is checked 100 frames after its last window began
  const uint64_t last = l.last_open_frame;
  const uint32_t campaign = l.opened;
  while (l.opened == campaign)
    l.frame(0.05 * f++, 2.0, good);
  LONGS_EQUAL(100, l.last_open_frame - last);
  // ... and the next check a whole period after that one
  const uint64_t first = l.last_open_frame;
  while (l.opened == campaign + 1)
    l.frame(0.05 * f++, 2.0, good);
  LONGS_EQUAL(5000, l.last_open_frame - first);
  // WHEN the model changes in operation (a calibration put in force)
  for (int n = 0; n < 1000; ++n)
    l.frame(0.05 * f++, 2.0, good);
  l.s.model_changed();
  const uint64_t changed = l.s.frames();
  while (l.opened == campaign + 2)
    l.frame(0.05 * f++, 2.0, good);
  // THEN its check comes 100 frames later, not at the period
  LONGS_EQUAL(100, l.last_open_frame - changed);
}

TEST(WindowScheduler, ContinuedIdentificationKeepsTheRunsExcitationOffShareAtTheDuty) {
  // GIVEN a campaign of 16 windows (2 per bin, 160 of ~850 frames off), then
  // continued identification at 2 % with a rare check (every 20000 frames)
  WindowConfig c = small_config();
  c.min_windows_per_bin = 2;
  c.check_period_frames = 20000;
  c.operation_duty = 0.02;
  Loop l(c);
  EstimatorHealth good{true, 50.0, 1.0};
  int f = 0;
  for (; !l.s.campaign_done() && f < 20000; ++f)
    l.frame(0.01 * f, 2.0, good);
  CHECK(l.s.campaign_done());
  CHECK(l.s.excitation_off_fraction() > 0.1);
  // THEN no window opens until the run's share has fallen to the duty
  const uint32_t before = l.opened;
  const auto due = static_cast<uint64_t>(static_cast<double>(l.s.off_frames()) / c.operation_duty);
  for (; l.s.frames() + c.length_frames + 1 < due; ++f)
    l.frame(0.01 * f, 2.0, good);
  LONGS_EQUAL(before, l.opened);
  // and from then on it stays at the duty (within one window) over a long
  // run: 10-frame windows every 500 frames.
  for (int n = 0; n < 100000; ++n, ++f)
    l.frame(0.01 * f, 2.0, good);
  CHECK(l.s.excitation_off_fraction() <= c.operation_duty + 1e-12);
  DOUBLES_EQUAL(c.operation_duty, l.s.excitation_off_fraction(),
                static_cast<double>(c.length_frames) / static_cast<double>(l.s.frames()));
  CHECK(l.opened - before >= 100000 / 500 - 1);
}

TEST(WindowScheduler, OperationWindowsHaveTheirOwnLength) {
  // GIVEN 10-frame campaign windows and 30-frame windows in operation
  WindowConfig c = small_config();
  c.check_period_frames = 500;
  c.operation_length_frames = 30;
  Loop l(c);
  EstimatorHealth good{true, 50.0, 1.0};
  for (int f = 0; f < 200; ++f)
    l.frame(0.05 * f, 2.0, good);
  CHECK(l.s.campaign_done());
  // THEN the next (check) window stays open 30 frames
  int opened_at = -1, closed_at = -1;
  for (int f = 0; f < 1000 && closed_at < 0; ++f) {
    const WindowDecision d = l.frame(10.0 + 0.05 * f, 2.0, good);
    if (d.open) opened_at = f;
    if (d.close) closed_at = f;
  }
  CHECK(opened_at >= 0);
  LONGS_EQUAL(30, closed_at - opened_at);
}

TEST(WindowScheduler, ChecksKeepTheirLengthWhileTheDutysWindowsAreLong) {
  // GIVEN 10-frame campaign windows, 10-frame checks every 500 frames and
  // 100-frame operation windows at 5 % excitation off
  WindowConfig c = small_config();
  c.check_period_frames = 500;
  c.check_length_frames = 10;
  c.operation_length_frames = 100;
  c.operation_duty = 0.05;
  Loop l(c);
  EstimatorHealth good{true, 50.0, 1.0};
  int f = 0;
  for (; f < 200; ++f)
    l.frame(0.05 * f, 2.0, good);
  CHECK(l.s.campaign_done());
  // WHEN the run goes on (the campaign's share falls below the duty)
  uint32_t short_windows = 0, long_windows = 0;
  int opened_at = -1;
  for (int n = 0; n < 200000; ++n, ++f) {
    const WindowDecision d = l.frame(0.05 * f, 2.0, good);
    if (d.open) opened_at = n;
    if (d.close) {
      const int length = n - opened_at;
      CHECK(length == 10 || length == 100);
      (length == 10 ? short_windows : long_windows) += 1;
    }
  }
  // THEN both kinds ran, and the share stays at the duty within one long
  // window although the checks are forced whatever the duty
  CHECK(short_windows > 0);
  CHECK(long_windows > 0);
  CHECK(l.s.excitation_off_fraction() <= c.operation_duty + 1e-12);
  DOUBLES_EQUAL(c.operation_duty, l.s.excitation_off_fraction(),
                100.0 / static_cast<double>(l.s.frames()));
  // and the long windows take what the checks leave of the duty: the checks
  // at most one per check period (10 / 500 = 2 %), so the long ones at least
  // (5 % - 2 %) of the frames less what the campaign took, at most 5 %.
  const double frames = static_cast<double>(l.s.frames());
  const double campaign_off = 200.0;  // at most 8 bins x 2 x 10 frames, plus the duty
  CHECK(static_cast<double>(long_windows) >=
        ((c.operation_duty - 10.0 / 500.0) * frames - campaign_off) / 100.0 - 1.0);
  CHECK(static_cast<double>(long_windows) <= c.operation_duty * frames / 100.0);
}

namespace {
// A still base whose pattern drifts back to one equilibrium angle between
// windows (at a tenth of the walk's rate) and follows a pattern command at
// the forcers' rate.
struct StillPattern {
  double theta_rad;
  double equilibrium_rad;
  double walk_rad_per_frame;
  void step(const WindowDecision& d) {
    const double target = d.pattern_command ? d.pattern_target_rad : equilibrium_rad;
    const double rate = d.pattern_command ? walk_rad_per_frame : 0.1 * walk_rad_per_frame;
    const double e = target - theta_rad;
    theta_rad += std::fabs(e) <= rate ? e : std::copysign(rate, e);
  }
};

struct StillRun {
  std::vector<uint32_t> bins;     // bin of each operation window
  std::array<uint32_t, 8> total;  // the scheduler's count per bin, campaign included
  uint32_t walk_frames = 0;
  uint32_t longest_walk_frames = 0;
};

// The operation windows of a still run after a campaign on a turning table.
StillRun still_run(bool rotate) {
  WindowConfig c = small_config();  // 8 bins
  c.operation_duty = 0.05;
  c.rotate_in_operation = rotate;
  c.max_walk_frames = 2000;
  Loop l(c);
  EstimatorHealth good{true, 50.0, 1.0};
  for (int f = 0; f < 400; ++f)
    l.frame(0.05 * f, 2.0, good);
  CHECK(l.s.campaign_done());
  // 0.1 deg of pattern angle per frame: an 11.25 deg bin in ~113 frames
  StillPattern p{0.3, 0.3, 0.1 * kPi / 180.0};
  StillRun r;
  uint32_t walk = 0;
  for (int f = 0; f < 60000; ++f) {
    const WindowDecision d = l.frame(p.theta_rad, 0.0, good);
    if (d.open) r.bins.push_back(l.s.bin_of(p.theta_rad));
    walk = d.pattern_command ? walk + 1 : 0;
    r.walk_frames += d.pattern_command ? 1 : 0;
    r.longest_walk_frames = std::max(r.longest_walk_frames, walk);
    p.step(d);
  }
  for (uint32_t b = 0; b < 8; ++b)
    r.total[b] = l.s.bin_count(b);
  return r;
}
}  // namespace

TEST(WindowScheduler, WithoutRotationTheOperationWindowsOfAStillRunSeeOneAngle) {
  const StillRun r = still_run(false);
  CHECK(r.bins.size() > 100);  // 5 % of 60000 frames in 10-frame windows: ~300
  for (uint32_t b : r.bins)
    LONGS_EQUAL(r.bins.front(), b);  // the equilibrium's bin, every time
  LONGS_EQUAL(0, r.walk_frames);
}

TEST(WindowScheduler, RotationInOperationSpreadsTheWindowsOverEveryBinEvenly) {
  // GIVEN a still run whose pattern returns to one angle between windows
  const StillRun r = still_run(true);
  CHECK(r.bins.size() > 100);
  // THEN the windows fill the 8 bins in turn: with the campaign's, every bin
  // holds the same count within one window, and the operation windows alone
  // at least their even share less the most the campaign put in one bin
  const auto [lo, hi] = std::minmax_element(r.total.begin(), r.total.end());
  CHECK(*hi - *lo <= 1);
  std::array<uint32_t, 8> ops{};
  for (uint32_t b : r.bins)
    ++ops[b];
  uint32_t campaign_max = 0;
  for (uint32_t b = 0; b < 8; ++b)
    campaign_max = std::max(campaign_max, r.total[b] - ops[b]);
  for (uint32_t b = 0; b < 8; ++b)
    CHECK(ops[b] + campaign_max >= r.bins.size() / 8);
  // and each walk is no longer than the farthest bin of a half circle takes
  // at the walk's rate (4 bins of 11.25 deg at 0.1 deg per frame: 450 frames)
  CHECK(r.walk_frames > 0);
  CHECK(r.longest_walk_frames <= 451);
}
