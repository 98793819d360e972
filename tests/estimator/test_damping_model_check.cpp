// SPDX-License-Identifier: MIT
// The damping model check (est::DampingModelCheck): windows at different
// temperatures over the 4theta circle, the resonator's common damping
// changing by (1 + beta_true dT), the calibration's scale (1 + beta_cal dT)
// in the samples. The fitted share f of the calibration's change is
// beta_true / beta_cal: 1 right, -1 wrong sign, 0 no such effect.
#include <cmath>
#include <cstdio>
#include <random>

#include <estimator/damping_model_check.hpp>
#include <estimator/drift.hpp>

#include "synthetic_decay.hpp"

#include "support/cpputest.hpp"

using namespace hrg::est;
using namespace hrg::est::test;

namespace {

constexpr double kBeta = 0.004;  // 1/degC, the thermal damping row's coefficient
constexpr int kWindows = 16;
constexpr int kSamples = 2000;    // 2 s at 1 kHz
constexpr double kNoiseV = 1e-4;  // per quadrature sample, on a 1 V wave

// Window k: pattern angle over the circle, temperature offset +-1 degC on a
// cycle of 7 windows (not tied to the angle).
double temperature_offset_c(int k) { return std::sin(2.0 * M_PI * k / 7.0); }

DampingModelCheckResult check(double beta_true, double beta_cal, uint64_t seed,
                              double noise_v = kNoiseV) {
  DampingModelCheck c;
  std::mt19937_64 rng(seed);
  const ParamVector p = seed_params(0.2, 0.5);
  for (int k = 0; k < kWindows; ++k) {
    const double theta0 = 0.05 + k * (M_PI / 2) / kWindows;
    const double dt_c = temperature_offset_c(k);
    const SyntheticDecay gen(with_damping_scale(p, 1.0 + beta_true * dt_c), 0.554, 0.0);
    DecayState s{10.0 * k, 1.0, 0.0, theta0};
    c.begin_window();
    for (int i = 0; i < kSamples; ++i) {
      gen.step(s, 1e-3);
      WaveSample w = gen.measure(s, noise_v, rng);
      w.damping_scale = 1.0 + beta_cal * dt_c;
      CHECK(c.add_sample(w) == Status::ok);
    }
    CHECK(c.end_window() == Status::ok);
  }
  return c.solve();
}

}  // namespace

TEST_GROUP(DampingModelCheck){};

TEST(DampingModelCheck, TheRightCoefficientIsSupportedAndAWrongSignRefuted) {
  const DampingModelCheckResult right = check(kBeta, kBeta, 1);
  const DampingModelCheckResult wrong = check(kBeta, -kBeta, 1);
  // Half the noise: sigma_f ~0.06, so f = 0 stands 8 sigma below 1/2.
  const DampingModelCheckResult absent = check(0.0, kBeta, 1, 0.5 * kNoiseV);
  std::printf("f: right %.3f +- %.3f, wrong sign %.3f, no thermal damping %.3f\n", right.factor,
              right.factor_sigma, wrong.factor, absent.factor);
  CHECK(right.status == Status::ok && wrong.status == Status::ok && absent.status == Status::ok);
  // sigma_f: per-window decay rate ~4e-6 1/s against a change nu beta dT of
  // 1.3e-5 1/s at 1 degC: ~0.1.
  CHECK(right.factor_sigma > 0.03 && right.factor_sigma < 0.3);
  CHECK(std::fabs(right.factor - 1.0) < 4.0 * right.factor_sigma);
  CHECK(right.supported && !right.refuted);
  CHECK(std::fabs(wrong.factor + 1.0) < 4.0 * wrong.factor_sigma);
  CHECK(wrong.refuted && !wrong.supported);
  CHECK(std::fabs(absent.factor) < 4.0 * absent.factor_sigma);
  CHECK(absent.refuted);
  DOUBLES_EQUAL(M_PI * 5000.0 / 5e6, right.nu_per_s, 1e-6);
}

TEST(DampingModelCheck, NothingToJudgeWithoutAChangeOrWithAConstantOne) {
  // k = 1: no model to check.
  CHECK(check(kBeta, 0.0, 2).status == Status::no_data);
  // Too few windows for a verdict.
  DampingModelCheck few;
  CHECK(few.solve().status == Status::no_data);
  CHECK(few.end_window() == Status::not_in_window);
}

TEST(DampingModelCheck, ItsSigmaHoldsSoTheStatedFalseAlarmRateHolds) {
  // 200 noise realisations with the right coefficient: (f - 1) / sigma_f is
  // standard normal when sigma_f is right (its sample standard deviation
  // within 0.8..1.25 at 200 draws: 3.5 sigma of its spread), so the
  // refutation at (1/2 - f) > 4 sigma_f has the stated size (Phi(-4) = 3.2e-5
  // at f = 1/2, less at f = 1); none of them is refuted.
  constexpr int kTrials = 200;
  double sum = 0.0, sum2 = 0.0;
  int refuted = 0;
  for (int i = 0; i < kTrials; ++i) {
    // A noisier chain: sigma_f ~0.3, so the check is exercised near its threshold.
    const DampingModelCheckResult r = check(kBeta, kBeta, 100 + i, 3.0 * kNoiseV);
    CHECK(r.status == Status::ok);
    const double z = (r.factor - 1.0) / r.factor_sigma;
    sum += z;
    sum2 += z * z;
    refuted += r.refuted ? 1 : 0;
  }
  const double mean = sum / kTrials;
  const double sd = std::sqrt(sum2 / kTrials - mean * mean);
  std::printf("(f - 1)/sigma_f over %d trials: mean %.3f, sd %.3f, refuted %d\n", kTrials, mean, sd,
              refuted);
  CHECK(std::fabs(mean) < 3.0 / std::sqrt(kTrials));
  CHECK(sd > 0.8 && sd < 1.25);
  CHECK(refuted == 0);
}
