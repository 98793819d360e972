// SPDX-License-Identifier: MIT
// The firmware's window plans: when the model a campaign applies is first
// checked, and how often after that.
#include "firmware/app/firmware_config.hpp"

#include <cmath>
#include <cstdint>

#include "support/window_loop.hpp"

#include "support/cpputest.hpp"

using hrg::fw::EstimatorHealth;
using hrg::fw::WindowConfig;
using hrg::fw::app::default_firmware_config;
using hrg::fw::app::kFirstCheckDelayFrames;
using hrg::fw::app::WindowPlan;
using hrg::test::WindowLoop;

namespace {

// Frames from the start of a plan's last campaign window to its first and
// second check windows, the table turning the pattern throughout.
struct CheckTimes {
  uint64_t first = 0;
  uint64_t second = 0;
  uint32_t first_length = 0;  // frames the first check stays open
};

const EstimatorHealth kGood{true, 10.0, 1.0};
// 0.1 rad/s of pattern angle: 4 theta turns every 16 s.
constexpr double kTurningRadS = 0.1;

// One frame of a table turning the pattern at kTurningRadS (frame f).
hrg::fw::WindowDecision turning(WindowLoop& l, uint64_t& f) {
  return l.frame(kTurningRadS * 1e-3 * static_cast<double>(f++), kTurningRadS, kGood);
}

CheckTimes check_times(const WindowConfig& w) {
  WindowLoop l(w);
  uint64_t f = 0;
  while (!l.s.campaign_done())
    turning(l, f);
  const uint64_t last = l.last_open_frame;
  const uint32_t campaign = l.opened;
  CheckTimes t;
  while (l.opened == campaign)
    turning(l, f);
  const uint64_t opened_at = l.s.frames();
  t.first = l.last_open_frame - last;
  while (!turning(l, f).close) {
  }
  t.first_length = static_cast<uint32_t>(l.s.frames() - opened_at);
  while (l.opened == campaign + 1)
    turning(l, f);
  t.second = l.last_open_frame - last;
  return t;
}

}  // namespace

TEST_GROUP(WindowPlan){};

TEST(WindowPlan, TheLongRunPlanChecksItsCampaignsModelAfterTheSettlingDelay) {
  // GIVEN the long-run plan: 5 s windows 10 s apart, checks every 10 min
  const WindowConfig w = default_firmware_config({}, WindowPlan::long_run).gyro.windows;
  LONGS_EQUAL(600000, w.check_period_frames);
  // THEN the first check opens 20 s after the campaign's last window began
  // (two window periods, not the 10 min period), for the plan's 5 s
  const CheckTimes t = check_times(w);
  LONGS_EQUAL(20000, kFirstCheckDelayFrames);
  LONGS_EQUAL(kFirstCheckDelayFrames, t.first);
  CHECK(t.first >= 2u * w.period_frames);
  LONGS_EQUAL(5000, t.first_length);
  // ... and the second one the long period after the first
  LONGS_EQUAL(t.first + w.check_period_frames, t.second);
}

TEST(WindowPlan, TheStandardPlanKeepsItsTwentySecondChecks) {
  // GIVEN the standard plan: 1 s windows 2 s apart, checks every 20 s
  const WindowConfig w = default_firmware_config({}, WindowPlan::standard).gyro.windows;
  // THEN its first check is 20 s after the last window began, as before the
  // settling delay existed, and the second 20 s after that
  const CheckTimes t = check_times(w);
  LONGS_EQUAL(20000, t.first);
  LONGS_EQUAL(1000, t.first_length);
  LONGS_EQUAL(40000, t.second);
}

TEST(WindowPlan, TheLongRunPlanChecksOnceTheBaseIsStillThoughItsRateIsNoisy) {
  // GIVEN the long-run plan after its campaign and first check, the table
  // turning
  const WindowConfig w = default_firmware_config({}, WindowPlan::long_run).gyro.windows;
  WindowLoop l(w);
  uint64_t f = 0;
  while (!l.s.campaign_done())
    turning(l, f);
  const uint32_t campaign = l.opened;
  while (l.opened == campaign || l.mode != hrg::fw::Mode::operate)
    turning(l, f);
  // WHEN the table stops, the rate read with a noise of 1.5e-3 rad/s
  // amplitude (above the 1e-3 limit half of the frames: the output's rate
  // over 10 ms on the 4.2 kHz resonator's parks, 1.4e-3 rms)
  const uint64_t stopped = l.s.frames();
  uint64_t opened_at = 0;
  for (int n = 0; n < 100000 && opened_at == 0; ++n) {
    const double noise_rad_s = 1.5e-3 * std::sin(2.0 * static_cast<double>(n));
    if (l.frame(1.0, noise_rad_s, kGood).open) opened_at = l.s.frames();
  }
  // THEN a check opens once the averaged rate has been still for a window
  // period (10 s), long before the 10 min period: averaging 0.2 s of rate
  // brings the noise far under the limit (unaveraged, no check in 100 s)
  CHECK(opened_at > 0);
  CHECK(opened_at - stopped >= w.period_frames);
  CHECK(opened_at - stopped <= w.period_frames + 5u * w.still_rate_average_frames);
}
