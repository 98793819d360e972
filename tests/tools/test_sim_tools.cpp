// SPDX-License-Identifier: MIT
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "sim_run/analysis.hpp"
#include "sim_run/json.hpp"

#include "support/cpputest.hpp"

using hrg::sim_run::allan_deviation;
using hrg::sim_run::fit_bias_4theta;

TEST_GROUP(AllanDeviation){};

TEST(AllanDeviation, WhiteRateNoiseFallsAsOneOverRootTau) {
  // GIVEN a rate with white noise sigma = 0.1 per 1 ms sample, integrated to an angle
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, 0.1);
  const double tau0 = 1e-3;
  std::vector<double> angle(200'001, 0.0);
  for (std::size_t i = 1; i < angle.size(); ++i)
    angle[i] = angle[i - 1] + noise(rng) * tau0;
  const auto adev = allan_deviation(angle, tau0);
  // THEN adev(m tau0) = sigma / sqrt(m) within the estimate's own scatter
  for (const auto& p : adev) {
    const double m = p.tau_s / tau0;
    if (m > 1000) break;
    const double expected = 0.1 / std::sqrt(m);
    const double rel_err = std::fabs(p.adev - expected) / expected;
    CHECK(rel_err < 4.0 / std::sqrt(static_cast<double>(p.terms) / m));
  }
  DOUBLES_EQUAL(1e-3, adev.front().tau_s, 0.0);
  DOUBLES_EQUAL(0.1, adev.front().adev, 0.002);
}

TEST(AllanDeviation, AConstantRateHasZeroDeviation) {
  std::vector<double> angle(1000);
  for (std::size_t i = 0; i < angle.size(); ++i)
    angle[i] = 0.25 * static_cast<double>(i);
  for (const auto& p : allan_deviation(angle, 1.0))
    DOUBLES_EQUAL(0.0, p.adev, 1e-9);
}

TEST_GROUP(BiasFit){};

TEST(BiasFit, RecoversOffsetAndFourThetaTermsFromSixteenAngles) {
  std::vector<double> th, b;
  for (int i = 0; i < 16; ++i) {
    const double t = i * std::numbers::pi / 32;  // 16 angles over a 4 theta turn
    th.push_back(t);
    b.push_back(3.0 + 50.0 * std::sin(4 * t) - 20.0 * std::cos(4 * t) + (i % 2 ? 0.1 : -0.1));
  }
  const auto f = fit_bias_4theta(th, b);
  CHECK(f.ok);
  DOUBLES_EQUAL(3.0, f.b0, 1e-9);
  DOUBLES_EQUAL(50.0, f.a_sin4, 0.05);
  DOUBLES_EQUAL(-20.0, f.b_cos4, 0.05);
  DOUBLES_EQUAL(std::hypot(50.0, 20.0), f.amplitude(), 0.1);
  DOUBLES_EQUAL(0.1, f.residual_rms, 0.02);
  CHECK(f.sigma_a > 0 && f.sigma_a < 0.1);
}

TEST(BiasFit, RefusesAnglesThatDoNotSpanFourTheta) {
  std::vector<double> th{0.0, std::numbers::pi / 2, std::numbers::pi, 1.5 * std::numbers::pi};
  std::vector<double> b{1, 2, 3, 4};
  CHECK_FALSE(fit_bias_4theta(th, b).ok);  // 4 theta is the same for all
}

TEST(BiasFit, EvenParksAreWellConditionedAndSpanTheTurn) {
  // 16 parks 5.625 deg apart: [1, sin 4th, cos 4th] orthogonal, scaled condition 1.
  std::vector<double> th, b;
  for (int i = 0; i < 16; ++i) {
    th.push_back(i * std::numbers::pi / 32);
    b.push_back(0.5 + 2.0 * std::sin(4 * th.back()));
  }
  const auto f = fit_bias_4theta(th, b);
  DOUBLES_EQUAL(1.0, f.condition, 1e-9);
  DOUBLES_EQUAL(90.0 * 15.0 / 16.0 * std::numbers::pi / 180.0, f.span_rad, 1e-12);
  CHECK_FALSE(f.degenerate());
  DOUBLES_EQUAL(0.5, f.park_mean, 1e-12);  // the sine averages out over the turn
}

namespace {
// Parks in three equal groups at 4 theta = -d, 0, +d: sin 4th is orthogonal
// to the rest and the (1, cos 4th) block of the scaled normal matrix is
// [1 r; r 1] with r = (1 + 2 cos d) / sqrt(3 (1 + 2 cos^2 d)): condition
// (1 + r) / (1 - r).
double three_group_condition(double d) {
  const double r =
      (1.0 + 2.0 * std::cos(d)) / std::sqrt(3.0 * (1.0 + 2.0 * std::cos(d) * std::cos(d)));
  return (1.0 + r) / (1.0 - r);
}
void three_groups(double d, std::vector<double>& th, std::vector<double>& b) {
  // bias 0.02 + 1.5 sin 4th (deg/h) plus errors of zero mean: +0.01 on the
  // outer groups and -0.02 on the middle one (the curvature a narrow set
  // cannot tell from cos 4th), +-0.001 alternating within each group
  for (int i = 0; i < 12; ++i) {
    const int group = i % 3 - 1;
    th.push_back(group * d / 4.0);
    const double error = (group == 0 ? -0.02 : 0.01) + ((i / 3) % 2 ? 0.001 : -0.001);
    b.push_back(0.02 + 1.5 * std::sin(4.0 * th.back()) + error);
  }
}
}  // namespace

TEST(BiasFit, ParksAtNearlyOneAngleAreDegenerateAndReportTheirMean) {
  // GIVEN parks within +-0.05 rad of 4 theta (+-0.7 deg of pattern angle)
  std::vector<double> th, b;
  const double d = 0.05;
  three_groups(d, th, b);
  const auto f = fit_bias_4theta(th, b);
  // THEN the fit's condition is the closed form's (1.2e7), far above the limit
  DOUBLES_EQUAL(1.0, f.condition / three_group_condition(d), 1e-6);
  CHECK(f.condition > 1e5);
  CHECK(f.degenerate());
  DOUBLES_EQUAL(2.0 * d / 4.0, f.span_rad, 1e-12);
  // the fit's offset and ADB are off by far more than the 0.02 of error (the
  // misleading pair), while the parks' plain mean is the true 0.02 (the sine
  // and the errors cancel over the groups), with the scatter's standard error
  CHECK(std::fabs(f.b0 - 0.02) > 1.0 || std::fabs(f.amplitude() - 1.5) > 1.0);
  DOUBLES_EQUAL(0.02, f.park_mean, 1e-12);
  double ss = 0.0;
  for (double v : b)
    ss += (v - 0.02) * (v - 0.02);
  DOUBLES_EQUAL(std::sqrt(ss / 11.0 / 12.0), f.sigma_park_mean, 1e-12);
}

TEST(BiasFit, TheDegenerateLimitSitsBetweenNarrowAndEvenParks) {
  // Three groups 120 deg of 4 theta apart: r = 0, condition 1; as the groups
  // close in, the condition crosses kMaxBiasFitCondition (r = 99/101).
  std::vector<double> th, b;
  three_groups(2.0 * std::numbers::pi / 3.0, th, b);
  DOUBLES_EQUAL(1.0, fit_bias_4theta(th, b).condition, 1e-9);
  CHECK_FALSE(fit_bias_4theta(th, b).degenerate());
  for (const double d : {0.6, 0.8, 1.0, 1.5}) {
    th.clear();
    b.clear();
    three_groups(d, th, b);
    const auto f = fit_bias_4theta(th, b);
    DOUBLES_EQUAL(1.0, f.condition / three_group_condition(d), 1e-6);
    CHECK_EQUAL(three_group_condition(d) > hrg::sim_run::kMaxBiasFitCondition, f.degenerate());
  }
}

TEST(BiasFit, TooFewParksAreNotCalledDegenerate) {
  // three parks: fewer than the fit needs, a coverage failure, not a narrow set
  std::vector<double> th{0.0, 0.001, 0.002}, b{1, 1, 1};
  const auto f = fit_bias_4theta(th, b);
  CHECK_FALSE(f.ok);
  CHECK_FALSE(f.degenerate());
  DOUBLES_EQUAL(1.0, f.park_mean, 1e-12);
}

TEST_GROUP(Slope){};

TEST(Slope, IsTheLeastSquaresSlope) {
  std::vector<double> t{0, 1, 2, 3}, y{1, 3, 5, 7};
  DOUBLES_EQUAL(2.0, hrg::sim_run::slope(t, y), 1e-12);
}

TEST_GROUP(JsonWriter){};

TEST(JsonWriter, WritesNestedObjectsArraysAndNullForNonFinite) {
  hrg::sim_run::JsonWriter w;
  w.begin_object();
  w.number("a", 1.5);
  w.begin_object("b");
  w.string("s", "x\"y");
  w.boolean("t", true);
  w.end_object();
  w.begin_array("c");
  w.number(1.0);
  w.number(NAN);
  w.end_array();
  w.end_object();
  STRCMP_EQUAL(
      "{\n  \"a\": 1.5,\n  \"b\": {\n    \"s\": \"x\\\"y\",\n    \"t\": true\n  },\n  \"c\": "
      "[\n    1,\n    null]\n}\n",
      w.str().c_str());
}
