// SPDX-License-Identifier: MIT
// Which part of a pickoff self-calibration estimate is put in force: each
// part weighted by its evidence, x max(0, 1 - sigma^2 / x^2)
// (estimator/pickoff_evidence.hpp).
#include <estimator/pickoff_evidence.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "support/cpputest.hpp"

using namespace hrg::est;

namespace {

// Mean |applied - truth| in sigmas over `draws` estimates x ~ N(truth, 1):
// the rule's and the whole estimate's.
struct MeanError {
  double weighted = 0.0;
  double whole = 0.0;
};

MeanError mean_error(double truth, int draws) {
  std::mt19937_64 rng(16);
  std::normal_distribution<double> n(truth, 1.0);
  MeanError e;
  for (int i = 0; i < draws; ++i) {
    const double x = n(rng);
    e.weighted += std::fabs(evidence_weighted(x, 1.0) - truth);
    e.whole += std::fabs(x - truth);
  }
  e.weighted /= draws;
  e.whole /= draws;
  return e;
}

}  // namespace

TEST_GROUP(PickoffEvidence){};

TEST(PickoffEvidence, AnEstimateWithinItsSigmaOfZeroIsNotApplied) {
  DOUBLES_EQUAL(0.0, evidence_weighted(0.0, 1e-5), 0.0);
  DOUBLES_EQUAL(0.0, evidence_weighted(0.8e-5, 1e-5), 0.0);
  DOUBLES_EQUAL(0.0, evidence_weighted(-1e-5, 1e-5), 0.0);
}

TEST(PickoffEvidence, AnEstimateOutOfItsNoiseIsAppliedLessItsNoiseShare) {
  // x (1 - sigma^2 / x^2): 3 sigma -> 8/3 sigma, either sign.
  DOUBLES_EQUAL(8.0 / 3.0 * 1e-5, evidence_weighted(3e-5, 1e-5), 1e-18);
  DOUBLES_EQUAL(-8.0 / 3.0 * 1e-5, evidence_weighted(-3e-5, 1e-5), 1e-18);
  // A 1 % gain at the 365 s run's 5e-6: 1 - 2.5e-7 of it.
  DOUBLES_EQUAL(0.01 * (1.0 - 2.5e-7), evidence_weighted(0.01, 5e-6), 1e-15);
  // An exact value (no noise) is applied whole.
  DOUBLES_EQUAL(0.5, evidence_weighted(0.5, 0.0), 0.0);
  CHECK_TRUE(std::isnan(evidence_weighted(std::numeric_limits<double>::quiet_NaN(), 1.0)));
}

TEST(PickoffEvidence, NoPartThereTheRuleAddsAThirdOfTheWholeEstimatesError) {
  // x ~ N(0, 1): the whole estimate errs by sqrt(2/pi) = 0.80 sigma on
  // average, the weighted one by 0.26 (estimator/pickoff_evidence.hpp).
  const MeanError e = mean_error(0.0, 200000);
  std::printf("\n  truth 0: mean error %.3f sigma weighted, %.3f whole\n", e.weighted, e.whole);
  DOUBLES_EQUAL(std::sqrt(2.0 / M_PI), e.whole, 0.01);
  DOUBLES_EQUAL(0.26, e.weighted, 0.01);
}

TEST(PickoffEvidence, APartAFewSigmaOutIsKeptNearlyWhole) {
  // At 2 sigma the rule errs by 1.00 sigma (its worst) against 0.80, at
  // 5 sigma by 0.85: a true part is not lost (a 5 sigma threshold would err
  // by 3.6 sigma at 4 sigma).
  const MeanError two = mean_error(2.0, 200000);
  const MeanError five = mean_error(5.0, 200000);
  std::printf("\n  truth 2 / 5 sigma: mean error %.3f / %.3f sigma weighted, %.3f whole\n",
              two.weighted, five.weighted, five.whole);
  DOUBLES_EQUAL(1.00, two.weighted, 0.02);
  DOUBLES_EQUAL(0.85, five.weighted, 0.02);
}

TEST(PickoffEvidence, TheWholeEstimateIsTheMapInForceComposedWithTheResidual) {
  // Gains compose, angles add; the gain's sigma is the residual's through
  // the gain in force.
  PickoffSelfCalResult r;
  r.status = Status::ok;
  r.gain = 1e-4;
  r.gain_sigma = 1e-5;
  r.misalignment_rad = -2e-3;
  r.misalignment_sigma_rad = 1e-5;
  r.phase_rad = 3e-6;
  r.phase_sigma_rad = 1e-5;
  const PickoffMap in_force{0.01, 0.01, -0.01};
  const PickoffMapEstimate e = whole_estimate(in_force, r);
  DOUBLES_EQUAL(1.01 * 1.0001 - 1.0, e.value.gain, 1e-15);
  DOUBLES_EQUAL(0.008, e.value.misalignment_rad, 1e-15);
  DOUBLES_EQUAL(-0.01 + 3e-6, e.value.phase_rad, 1e-15);
  DOUBLES_EQUAL(1.01e-5, e.sigma.gain, 1e-18);
  // Weighted: every part stands out except nothing; the phase moves back
  // by its share, 1 - (1e-5)^2 / (0.009997)^2.
  const PickoffMap w = evidence_weighted_map(in_force, r);
  DOUBLES_EQUAL(e.value.phase_rad * (1.0 - 1e-10 / (e.value.phase_rad * e.value.phase_rad)),
                w.phase_rad, 1e-15);
  // The step back to it from the map in force: gain ratio, angle differences.
  const PickoffSelfCalResult s = step_between(in_force, w, r);
  DOUBLES_EQUAL((1.0 + w.gain) / 1.01 - 1.0, s.gain, 1e-15);
  DOUBLES_EQUAL(w.misalignment_rad - 0.01, s.misalignment_rad, 1e-15);
  DOUBLES_EQUAL(r.gain_sigma, s.gain_sigma, 0.0);
}
