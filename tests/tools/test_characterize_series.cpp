// SPDX-License-Identifier: MIT
// IEEE 1431 scale-factor series on steps whose answer is known.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "characterize/harmonic_fit.hpp"
#include "characterize/scale_factor.hpp"

#include "support/cpputest.hpp"

using namespace hrg::characterize;

namespace {
constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// +-5 ... +-300 deg/s: both signs over 1.78 decades.
std::vector<double> table_rates_rad_s() {
  std::vector<double> r;
  for (const double d : {5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 300.0}) {
    r.push_back(d * kRadPerDeg);
    r.push_back(-d * kRadPerDeg);
  }
  return r;
}

// Steps of a gyro output = bias + K in (1 + asym/2 sign(in)) + c3 in^3, plus
// white noise of the given standard error.
std::vector<RateStep> steps_of(double k, double bias, double asym, double c3, double sigma,
                               unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<RateStep> out;
  for (const double in : table_rates_rad_s()) {
    const double k_side = k * (1.0 + 0.5 * asym * (in > 0 ? 1.0 : -1.0));
    out.push_back({in, bias + k_side * in + c3 * in * in * in + (sigma > 0 ? g(rng) : 0.0), sigma});
  }
  return out;
}
}  // namespace

TEST_GROUP(ScaleFactor){};

TEST(ScaleFactor, RecoversKAndBiasWithinTheirStatedSigma) {
  // GIVEN K = 1 + 150 ppm, bias 0.01 deg/s, steps read to 2e-4 deg/s
  const double k = 1.000150, bias = 0.01 * kRadPerDeg, sigma = 2e-4 * kRadPerDeg;
  const auto r = analyze_scale_factor(steps_of(k, bias, 0.0, 0.0, sigma, 1));
  CHECK_TEXT(r.ok, r.error.c_str());
  // THEN the stated sigma is the closed form sigma / sqrt(sum in^2) (the rates are symmetric)...
  double sxx = 0;
  for (const double in : table_rates_rad_s())
    sxx += in * in;
  DOUBLES_EQUAL(sigma / std::sqrt(sxx), r.sigma_k, 1e-6 * r.sigma_k);
  // ...and K, its error and the bias are within 3 of them
  std::printf("\n  K error %.2f +- %.2f ppm (truth 150); bias %.5f +- %.5f deg/s (0.01)",
              r.k_error_ppm, r.sigma_k_error_ppm, r.bias_rad_s / kRadPerDeg,
              r.sigma_bias_rad_s / kRadPerDeg);
  DOUBLES_EQUAL(150.0, r.k_error_ppm, 3.0 * r.sigma_k_error_ppm);
  DOUBLES_EQUAL(bias, r.bias_rad_s, 3.0 * r.sigma_bias_rad_s);
  DOUBLES_EQUAL(0.0, r.asymmetry_ppm, 3.0 * r.sigma_asymmetry_ppm);
  DOUBLES_EQUAL(1.778, r.decades, 1e-3);
}

TEST(ScaleFactor, NonlinearityIsTheCubicsDepartureFromTheBestLine) {
  // GIVEN a cubic c3 in^3 reaching 200 ppm of full scale at 300 deg/s
  const double fs = 300.0 * kRadPerDeg;
  const double c3 = 200e-6 * fs / (fs * fs * fs);
  const auto r = analyze_scale_factor(steps_of(1.0, 0.0, 0.0, c3, 1e-6 * kRadPerDeg, 2));
  CHECK_TEXT(r.ok, r.error.c_str());
  // THEN the line takes c3 sum(in^4) / sum(in^2) into K, and the largest
  // departure left is c3 (in^3 - in sum(in^4)/sum(in^2)) over the steps.
  double s2 = 0, s4 = 0;
  for (const double in : table_rates_rad_s())
    s2 += in * in, s4 += in * in * in * in;
  double worst = 0;
  for (const double in : table_rates_rad_s())
    worst = std::max(worst, std::fabs(c3 * (in * in * in - in * s4 / s2)) / fs * 1e6);
  std::printf(
      "\n  nonlinearity %.2f +- %.2f ppm FS at %.0f deg/s (closed form %.2f); K error %.2f"
      " ppm (closed form %.2f)",
      r.nonlinearity_ppm, r.sigma_nonlinearity_ppm, r.worst_input_rad_s / kRadPerDeg, worst,
      r.k_error_ppm, c3 * s4 / s2 * 1e6);
  DOUBLES_EQUAL(worst, r.nonlinearity_ppm, 3.0 * r.sigma_nonlinearity_ppm);
  DOUBLES_EQUAL(c3 * s4 / s2 * 1e6, r.k_error_ppm, 3.0 * r.sigma_k_error_ppm);
  CHECK(r.nonlinearity_ppm > 40.0);  // the line takes most of it: 47.6 ppm remain
}

TEST(ScaleFactor, AsymmetryBetweenTheSigns) {
  // GIVEN K+ - K- = 80 ppm of K, steps read to 1e-4 deg/s
  const auto r = analyze_scale_factor(steps_of(1.0, 0.0, 80e-6, 0.0, 1e-4 * kRadPerDeg, 3));
  CHECK_TEXT(r.ok, r.error.c_str());
  std::printf("\n  asymmetry %.2f +- %.2f ppm (truth 80)", r.asymmetry_ppm, r.sigma_asymmetry_ppm);
  DOUBLES_EQUAL(80.0, r.asymmetry_ppm, 3.0 * r.sigma_asymmetry_ppm);
  CHECK(r.sigma_asymmetry_ppm < 10.0);
}

TEST(ScaleFactor, RefusesASeriesThatIsNotOne) {
  std::vector<RateStep> one_sign, narrow;
  for (const double d : {5.0, 50.0, 300.0})
    one_sign.push_back({d, d, 0.0});
  for (const double d : {10.0, 20.0, -10.0, -20.0})
    narrow.push_back({d, d, 0.0});
  const auto a = analyze_scale_factor(one_sign);
  const auto b = analyze_scale_factor(narrow);
  CHECK_FALSE(a.ok);
  CHECK_FALSE(b.ok);
  STRCMP_CONTAINS("each sign", a.error.c_str());
  STRCMP_CONTAINS("1.5", b.error.c_str());
}

TEST_GROUP(AngleReadout){};

TEST(AngleReadout, APickoffGainMismatchShowsAsItsFourThetaError) {
  // GIVEN pickoffs x = (1 + g) cos 2theta, y = sin 2theta with g = 1 % and the
  // pattern read as atan2(y, x) / 2 over two whole turns, with 1e-5 rad noise
  const double g = 0.01;
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, 1e-5);
  std::vector<double> truth, readout;
  for (int i = 0; i < 720; ++i) {
    const double th = i * std::numbers::pi / 180.0;
    double rd = 0.5 * std::atan2(std::sin(2 * th), (1 + g) * std::cos(2 * th));
    rd += std::round((th - rd) / std::numbers::pi) * std::numbers::pi;  // unwrap to theta's turn
    truth.push_back(th);
    readout.push_back(rd + noise(rng));
  }
  const auto r = analyze_angle_readout(truth, readout);
  CHECK_TEXT(r.ok, r.error.c_str());
  // THEN tan 2th_r = tan 2th / (1 + g) gives th_r - th = sum_n q^n sin(4 n th) / (2 n),
  // q = -g / (2 + g): the 4 theta harmonic is exactly g / (2 (2 + g)) (g / 4 to first order).
  const double expected_deg = g / (2.0 * (2.0 + g)) / kRadPerDeg;
  std::printf(
      "\n  4theta readout error %.5f +- %.5f deg (closed form %.5f); scale swing %.0f +- %.0f"
      " ppm",
      r.amplitude_deg, r.sigma_amplitude_deg, expected_deg, r.scale_swing_ppm,
      r.sigma_scale_swing_ppm);
  DOUBLES_EQUAL(expected_deg, r.amplitude_deg, 3.0 * r.sigma_amplitude_deg + 1e-4 * expected_deg);
  // The error is -A sin 4theta: phase pi (a < 0, b = 0), no scale error over whole turns.
  DOUBLES_EQUAL(std::numbers::pi, std::fabs(r.fit.harmonics[0].phase_rad), 1e-3);
  DOUBLES_EQUAL(0.0, r.mean_scale_error_ppm, 3.0 * r.fit.sigma_slope * 1e6);
}

TEST(AngleReadout, HarmonicFitRefusesAnglesThatDoNotSpanTheHarmonic) {
  // Parked at 0 and 90 deg only: sin 4theta is zero on both, so it cannot be told apart.
  const std::vector<double> th{0.0, 0.0, std::numbers::pi / 2, std::numbers::pi / 2};
  const std::vector<double> y{1.0, 1.1, 1.0, 0.9};
  const int orders[] = {4};
  const auto f = fit_harmonics(th, y, orders);
  CHECK_FALSE(f.ok);
  STRCMP_CONTAINS("span", f.error.c_str());
}
