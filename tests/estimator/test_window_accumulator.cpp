// SPDX-License-Identifier: MIT
#include <estimator/window_accumulator.hpp>

#include <cmath>
#include <random>

#include "synthetic_decay.hpp"
#include "window_runner.hpp"

#include "support/cpputest.hpp"

using namespace hrg::est;
using namespace hrg::est::test;

namespace {
// Residual sum of squares of the window's rows at parameters p.
double rss_at(const WindowContribution& w, const ParamVector& p) {
  const ParamVector b = w.info.block<kParams, 1>(0, kParams);
  const ParamMatrix n = w.info.block<kParams, kParams>(0, 0);
  return w.info(kParams, kParams) - 2.0 * p.dot(b) + p.dot(n * p);
}
}  // namespace

TEST_GROUP(WindowAccumulator) {
  ParamVector p = seed_params(0.2, 0.5);
  SyntheticDecay gen{p, 0.554, 0.0};
  std::mt19937_64 rng{1};
};

TEST(WindowAccumulator, SamplesInsideTheSettleTimeAreIgnoredByRule) {
  // GIVEN a 20 ms settle time and 1 kHz samples starting 1 ms after the switch
  WindowAccumulator acc;
  acc.begin_window(0.0);
  DecayState s{0.0, 1.0, 0.0, 0.1};
  int settling = 0;
  for (int i = 0; i < 100; ++i) {
    gen.step(s, 1e-3);
    if (acc.add_sample(gen.measure(s, 0.0, rng)) == Status::settling) ++settling;
  }
  // THEN the samples at t < 20 ms (19 or 20 of them, by rounding of 20 x 1 ms) are rejected
  CHECK(settling >= 19 && settling <= 20);
  CHECK_EQUAL(settling, acc.settling_samples_rejected());
  // AND the rest form (100 - settling) / 10 whole blocks
  CHECK_EQUAL((100 - settling) / 10, acc.blocks());
}

TEST(WindowAccumulator, ATimeGapAbortsTheWindow) {
  WindowAccumulator acc;
  acc.begin_window(0.0);
  CHECK(acc.add_sample({0.10, 1.0, 0.0, 0.0, 1.0}) == Status::ok);
  CHECK(acc.add_sample({0.101, 1.0, 0.0, 0.0, 1.0}) == Status::ok);
  CHECK(acc.add_sample({0.101, 1.0, 0.0, 0.0, 1.0}) == Status::time_not_increasing);
  CHECK(acc.add_sample({0.2, 1.0, 0.0, 0.0, 1.0}) == Status::gap);
  CHECK_FALSE(acc.window_open());
  WindowContribution w;
  CHECK(acc.end_window(w) == Status::not_in_window);
}

TEST(WindowAccumulator, ABadSampleAbortsTheWindow) {
  WindowAccumulator acc;
  acc.begin_window(0.0);
  CHECK(acc.add_sample({0.1, 0.0, 0.0, 0.0, 1.0}) == Status::bad_sample);
  CHECK_FALSE(acc.window_open());
  acc.begin_window(0.0);
  CHECK(acc.add_sample({0.1, 1.0, NAN, 0.0, 1.0}) == Status::bad_sample);
  CHECK(acc.begin_window(0.0) == Status::ok);
  CHECK(acc.begin_window(0.0) == Status::in_window);
}

TEST(WindowAccumulator, AWindowShorterThanTheMinimumIsDropped) {
  WindowAccumulator acc;  // min 5 blocks of 10 samples after 20 ms
  NormalEquations ls;
  WindowPlan plan;
  plan.duration_s = 0.060;  // 40 settled samples = 4 blocks
  CHECK(run_window(gen, 0.0, 0.1, plan, acc, ls, rng) == Status::too_short);
  plan.duration_s = 0.071;
  CHECK(run_window(gen, 0.0, 0.1, plan, acc, ls, rng) == Status::ok);
  DOUBLES_EQUAL(1.0, ls.windows(), 0.0);
}

TEST(WindowAccumulator, NoiseFreeRowsSatisfyEquation8AtTheTrueParameters) {
  // GIVEN a noise-free 3 s window with a_B/a_A = 0.05 at the switch and the
  // pattern precessing at 10 deg/s input rate
  SyntheticDecay moving{p, 0.554, 10.0 * M_PI / 180.0};
  WindowAccumulator acc;
  acc.begin_window(0.0);
  DecayState s{0.0, 1.0, 0.05, 0.3};
  for (int i = 0; i < 3000; ++i) {
    moving.step(s, 1e-3);
    acc.add_sample(moving.measure(s, 0.0, rng));
  }
  WindowContribution w;
  CHECK(acc.end_window(w) == Status::ok);
  // THEN the E and Q rows hold at the true p: the residual is a tiny fraction
  // of the rows' energy (trapezoid error O(dt^2))
  const double rss_true = rss_at(w, p);
  const double rss_zero = rss_at(w, ParamVector::Zero());
  CHECK(rss_zero > 0);
  CHECK(rss_true < 1e-9 * rss_zero);
  // AND a wrong split (dw_C off by 1 %) is clearly worse
  ParamVector wrong = p;
  wrong(kDwC) *= 1.01;
  CHECK(rss_at(w, wrong) > 1e3 * rss_true);
  // AND the window statistics are those of the window
  DOUBLES_EQUAL(2.98, w.duration_s, 1.5e-3);
  DOUBLES_EQUAL(2.0 * 298, w.rows, 0.0);
  DOUBLES_EQUAL(2.0, w.intercepts, 0.0);
  DOUBLES_EQUAL(1.0, w.mean_E_v2, 0.02);
}

TEST(WindowAccumulator, CoverageCountsSettledSecondsInTheBinOf4Theta) {
  WindowAccumulator acc;
  acc.begin_window(0.0);
  DecayState s{0.0, 1.0, 0.0, 0.3};  // 4theta = 1.2 rad -> bin 3 of 16
  for (int i = 0; i < 1000; ++i) {
    gen.step(s, 1e-3);
    acc.add_sample(gen.measure(s, 0.0, rng));
  }
  WindowContribution w;
  CHECK(acc.end_window(w) == Status::ok);
  CHECK_EQUAL(3, coverage_bin(0.3));
  DOUBLES_EQUAL(w.duration_s, w.coverage_s[3], 1e-3);
  CHECK_EQUAL(15, coverage_bin(-0.01));
  CHECK_EQUAL(0, coverage_bin(M_PI / 2 + 0.01));
}
