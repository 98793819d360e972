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
