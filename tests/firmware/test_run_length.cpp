// SPDX-License-Identifier: MIT
// Long runs (issue 19). The run length a resonator needs: the model's bias uncertainty
// after each accepted solve, and when it reaches the goal, measured or
// extrapolated from the growth of its information 1/sigma^2 (one more window
// at the schedule in force adds the same information).
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "firmware/app/firmware_config.hpp"
#include "sim_run/report.hpp"
#include "sim_run/run.hpp"

#include "support/cpputest.hpp"

namespace {
using hrg::sim_run::ConvergencePoint;
using hrg::sim_run::RunConfig;
using hrg::sim_run::RunResult;
using hrg::sim_run::uncertainty_goal_time;

// The default job with the relaxed resonator (Q 1e6, dmu 0.15, split 5e-3 Hz;
// ideal electrode, default ADC); duration 0: the 365 s main job.
RunConfig relaxed_job(double duration_s) {
  RunConfig j = hrg::sim_run::default_run(duration_s, 16);
  j.sim.resonator.q = 1.0e6;
  j.sim.resonator.dmu = 0.15;
  j.sim.resonator.split_hz = 5.0e-3;
  j.firmware.chain.q_factor = 1.0e6;
  hrg::sim_run::derive_firmware_config(j);
  return j;
}

// First time the record's uncertainty is at or below target_dph (-1: never).
double crossing_s(const std::vector<ConvergencePoint>& c, double target_dph) {
  for (const ConvergencePoint& p : c)
    if (p.bias_sigma_dph <= target_dph) return p.t_s;
  return -1.0;
}
}  // namespace

TEST_GROUP_WITHOUT_LEAK_CHECK(RunLength);

TEST(RunLength, InformationGrowingAtAConstantRateIsExtrapolatedExactly) {
  // GIVEN sigma(t) = s0 / sqrt((t - t0) / 1 s): information (t - t0) / s0^2,
  // a solve every 10 s from 100 s to 500 s
  const double s0 = 20.0, t0 = 50.0;
  std::vector<ConvergencePoint> c;
  for (double t = 100.0; t <= 500.0; t += 10.0)
    c.push_back({t, s0 / std::sqrt(t - t0)});
  // THEN the goal below the last point is reached at t0 + s0^2 / target^2
  const double target = 0.5;
  const auto g = uncertainty_goal_time(c, target);
  CHECK(g.extrapolated);
  DOUBLES_EQUAL(t0 + s0 * s0 / (target * target), g.t_s, 1e-6);
  // and a goal the record reached is the first solve at or below it
  const auto m = uncertainty_goal_time(c, s0 / std::sqrt(200.0 - t0));
  CHECK_FALSE(m.extrapolated);
  DOUBLES_EQUAL(200.0, m.t_s, 1e-9);
  // and three points give no estimate
  const std::vector<ConvergencePoint> few(c.begin(), c.begin() + 3);
  DOUBLES_EQUAL(-1.0, uncertainty_goal_time(few, target).t_s, 0.0);
}

TEST(RunLength, TheRelaxedResonatorsUncertaintyReachesTheGoalWhenItsConvergencePredicts) {
  // GIVEN the relaxed resonator's 365 s job with a goal of 0.9 deg/h, whose
  // third (0.3 deg/h) its model's uncertainty has not reached at the end
  RunConfig j = relaxed_job(0.0);
  j.bias_goal_dph = 0.9;
  const double target_dph = j.bias_goal_dph / 3.0;
  RunResult r = hrg::sim_run::run_simulation(j, {});
  CHECK(r.convergence.size() >= 10);
  CHECK(r.convergence.back().bias_sigma_dph > target_dph);
  // THEN the time it will is extrapolated beyond the run
  CHECK(r.t_bias_goal_extrapolated);
  CHECK(r.t_bias_goal_s > j.duration_s);
  // and the length needed is the bias test started then (the model is valid
  // before), said in the report
  CHECK(r.t_model_valid_s >= 0.0 && r.t_model_valid_s < r.t_bias_goal_s);
  DOUBLES_EQUAL(std::ceil(j.duration_s + r.t_bias_goal_s - j.parks.front().t_begin_s),
                r.bias_test_needs_s, 0.0);
  CHECK(hrg::sim_run::bias_test_coverage(r).find("from its convergence so far") !=
        std::string::npos);
  // AND a 1200 s run of the same resonator reaches it within 25 % of that
  // time (the information grows with the windows; the parks' new angles
  // make it grow unevenly)
  const RunResult longer = hrg::sim_run::run_simulation(relaxed_job(1200.0), {});
  const double reached_s = crossing_s(longer.convergence, target_dph);
  std::printf(
      "\nrelaxed resonator: bias uncertainty %.3f deg/h at %.0f s; %.2f deg/h predicted "
      "at %.0f s, reached at %.0f s in a 1200 s run\n",
      r.convergence.back().bias_sigma_dph, r.convergence.back().t_s, target_dph, r.t_bias_goal_s,
      reached_s);
  CHECK(reached_s > j.duration_s);
  DOUBLES_EQUAL(reached_s, r.t_bias_goal_s, 0.25 * reached_s);
}

TEST_GROUP_WITHOUT_LEAK_CHECK(LongRunPlan);

TEST(LongRunPlan, OperationWindowsLoseATenthOfTheAmplitudeAtMost) {
  // The long-run plan: 30 s operation windows, checks in the campaign's 5 s.
  hrg::fw::app::FirmwareConfig f =
      hrg::fw::app::default_firmware_config({}, hrg::fw::app::WindowPlan::long_run);
  const hrg::fw::WindowConfig& w = f.gyro.windows;
  LONGS_EQUAL(5000, w.check_length_frames);
  // The seed's resonator (Q 5e6 at 5 kHz): decay time Q / (pi f) = 318 s,
  // a tenth of it above the plan's 30 s: kept.
  LONGS_EQUAL(30000, w.operation_length_frames);
  // Q 1e6: 63.7 s, the windows cut to 6.37 s (exp(-0.1): 9.5 % amplitude lost).
  f.chain.q_factor = 1.0e6;
  hrg::fw::app::derive(f, {});
  const double decay_s = 1.0e6 / (std::numbers::pi * f.chain.f_center_hz);
  DOUBLES_EQUAL(0.1 * decay_s * 1000.0, f.gyro.windows.operation_length_frames, 1.0);
  // Q 1e5: never below the campaign's windows.
  f.chain.q_factor = 1.0e5;
  hrg::fw::app::derive(f, {});
  LONGS_EQUAL(f.gyro.windows.length_frames, f.gyro.windows.operation_length_frames);
}
