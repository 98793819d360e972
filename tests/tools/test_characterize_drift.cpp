// SPDX-License-Identifier: MIT
// IEEE 1431 drift-rate series helpers and the whole-angle limits, against
// closed forms and the resonator equations of shared/docs/physics.md.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "characterize/drift_series.hpp"
#include "characterize/whole_angle_limits.hpp"

#include "support/cpputest.hpp"

using namespace hrg::characterize;

namespace {
constexpr double kDegPerHourPerRadS = 180.0 / std::numbers::pi * 3600.0;

// The seed paper's example resonator (physics.md section 6): f 5000 Hz,
// Q 5e6, dQ/Q = 0.1 (dmu = 0.05), Bryan factor K/2 = 0.277.
constexpr double kF = 5000.0, kQ = 5e6, kDmu = 0.05, kK = 0.554;

// theta' = -(K Omega - nu dmu sin 4(theta - th_mu)) / 2 (eq. 7 with the damping
// drift only), RK4; returns the pattern angle after t_s.
double precess(double omega, double nu, double dmu, double t_s, double dt) {
  auto rate = [&](double th) { return -(kK * omega - nu * dmu * std::sin(4.0 * th)) / 2.0; };
  double th = 0.3;
  for (double t = 0; t < t_s; t += dt) {
    const double k1 = rate(th), k2 = rate(th + 0.5 * dt * k1), k3 = rate(th + 0.5 * dt * k2),
                 k4 = rate(th + dt * k3);
    th += dt * (k1 + 2 * k2 + 2 * k3 + k4) / 6.0;
  }
  return th;
}
}  // namespace

TEST_GROUP(Repeatability){};

TEST(Repeatability, StdAndItsIntervalFromTwentyTurnOns) {
  // 99 % interval: this seed's spread happens to be 40 % high (2.5 sigma for N = 20).
  std::mt19937_64 rng(17);
  std::normal_distribution<double> g(3.0, 0.5);
  std::vector<double> b(20);
  for (double& v : b)
    v = g(rng);
  const auto r = bias_repeatability(b, 0.99);
  CHECK_TEXT(r.ok, r.error.c_str());
  std::printf("\n  repeatability %.3f [%.3f, %.3f] deg/h (truth 0.5), mean %.3f +- %.3f (3)", r.std,
              r.std_lo, r.std_hi, r.mean, r.sigma_mean);
  CHECK(r.std_lo < 0.5 && 0.5 < r.std_hi);
  CHECK(r.std_lo < r.std && r.std < r.std_hi);
  DOUBLES_EQUAL(3.0, r.mean, 3.0 * r.sigma_mean);
}

TEST(Repeatability, TheIntervalCoversTheTruthAtItsStatedRate) {
  std::mt19937_64 rng(18);
  std::normal_distribution<double> g(0.0, 1.0);
  int covered = 0;
  const int trials = 1000;
  for (int t = 0; t < trials; ++t) {
    std::vector<double> b(8);
    for (double& v : b)
      v = g(rng);
    const auto r = bias_repeatability(b);
    covered += (r.std_lo <= 1.0 && 1.0 <= r.std_hi) ? 1 : 0;
  }
  std::printf("\n  68.3 %% interval of the std covers the truth in %.3f of %d", covered / 1000.0,
              trials);
  DOUBLES_EQUAL(0.683, covered / 1000.0, 0.045);  // 3 binomial sigmas
}

TEST(Repeatability, RefusesOneTurnOn) {
  const std::vector<double> b{1.0};
  const auto r = bias_repeatability(b);
  CHECK_FALSE(r.ok);
  STRCMP_CONTAINS("2 turn-ons", r.error.c_str());
}

TEST_GROUP(TemperatureSlope){};

TEST(TemperatureSlope, RecoversAKnownSlopeWithinItsSigma) {
  // GIVEN 0.02 deg/h per degC from -40 to +80 degC in 10 degC steps, 0.05 deg/h noise
  std::mt19937_64 rng(19);
  std::normal_distribution<double> g(0.0, 0.05);
  std::vector<double> temp, bias;
  for (double t = -40; t <= 80; t += 10) {
    temp.push_back(t);
    bias.push_back(1.0 + 0.02 * t + g(rng));
  }
  const auto r = bias_temperature_slope(temp, bias);
  CHECK_TEXT(r.ok, r.error.c_str());
  std::printf("\n  slope %.5f +- %.5f deg/h/degC (truth 0.02)", r.slope_per_degc,
              r.sigma_slope_per_degc);
  DOUBLES_EQUAL(0.02, r.slope_per_degc, 3.0 * r.sigma_slope_per_degc);
  // The stated sigma is the closed form sigma / sqrt(sum (T - mean)^2) = 0.05 / sqrt(18200),
  // its estimate scattering by about 1 / sqrt(2 (N - 2)) = 21 %.
  DOUBLES_EQUAL(0.05 / std::sqrt(18200.0), r.sigma_slope_per_degc, 0.5 * 0.05 / std::sqrt(18200.0));
}

TEST(TemperatureSlope, RefusesOneTemperature) {
  const std::vector<double> t{20, 20, 20}, b{1, 2, 3};
  const auto r = bias_temperature_slope(t, b);
  CHECK_FALSE(r.ok);
  STRCMP_CONTAINS("one temperature", r.error.c_str());
}

TEST_GROUP(RateThreshold){};

TEST(RateThreshold, ThePatternStopsWhereTheInputMeetsTheDampingDrift) {
  const double nu = damping_rate_per_s(kF, kQ);
  DOUBLES_EQUAL(std::numbers::pi * 1e-3, nu, 1e-15);  // physics.md: nu = pi 1e-3 1/s
  const double th = rate_threshold_rad_s(nu, kDmu, kK);
  std::printf("\n  seed resonator: nu dmu = %.3e rad/s, rate threshold %.1f deg/h", nu * kDmu,
              th * kDegPerHourPerRadS);
  DOUBLES_EQUAL(nu * kDmu / kK, th, 1e-18);
  // Below: the pattern is caught; it moves less than one 4 theta cycle and
  // then stands still (where sin 4theta = K Omega / (nu dmu)) while the free
  // pattern would turn by K Omega t / 2 = 2.6 rad more; above: it precesses
  // at the Adler rate.
  const double t_run = 20.0 / (nu * kDmu);
  const double caught = precess(0.95 * th, nu, kDmu, t_run, 1.0);
  const double still = precess(0.95 * th, nu, kDmu, 2 * t_run, 1.0);
  CHECK(std::fabs(caught - 0.3) < std::numbers::pi / 2);
  DOUBLES_EQUAL(0.95, std::sin(4 * still), 1e-6);
  DOUBLES_EQUAL(caught, still, 1e-4);
  for (const double over : {1.05, 1.5, 3.0}) {
    const double mean_rate = mean_precession_rate_rad_s(over * th, nu, kDmu, kK);
    const double travelled = precess(over * th, nu, kDmu, t_run * 5, 1.0) - 0.3;
    std::printf("\n  %.2f x threshold: mean rate %.4e rad/s (closed form %.4e)", over,
                travelled / (t_run * 5), mean_rate);
    DOUBLES_EQUAL(mean_rate, travelled / (t_run * 5), 0.01 * std::fabs(mean_rate) + 1e-9);
  }
}

TEST(RateThreshold, CompensationMovesItWithTheResidualAnisotropy) {
  // An identification to 10 % of dmu leaves a threshold 10 times lower: a
  // rate of 0.2 x the raw threshold is followed once compensated.
  const double nu = damping_rate_per_s(kF, kQ);
  const double raw = rate_threshold_rad_s(nu, kDmu, kK);
  const double residual = rate_threshold_rad_s(nu, 0.1 * kDmu, kK);
  DOUBLES_EQUAL(0.1 * raw, residual, 1e-18);
  const double t_run = 200.0 / (nu * kDmu);
  const double followed = precess(0.2 * raw, nu, 0.1 * kDmu, t_run, 1.0) - 0.3;
  const double expected = mean_precession_rate_rad_s(0.2 * raw, nu, 0.1 * kDmu, kK) * t_run;
  DOUBLES_EQUAL(expected, followed, 0.02 * std::fabs(expected));
  CHECK(std::fabs(followed) > std::numbers::pi / 2);
}

TEST_GROUP(RunDown){};

TEST(RunDown, MatchesTheFreeDecayEquations) {
  // The amplitude a' = -nu (1 + dmu cos 4(th - th_mu)) a and the pattern drift
  // th' = nu dmu sin 4(th - th_mu) / 2 (physics.md eqs. 7-8, Omega = 0), RK4,
  // against the closed form from the damping axes.
  const double nu = damping_rate_per_s(kF, kQ), th_mu = 0.2, floor = 1e-4;
  for (const double th0 : {0.2, 0.2 + std::numbers::pi / 8, 0.5, 0.9}) {
    double a = 1.0, th = th0, t = 0.0;
    const double dt = 0.5;
    auto da = [&](double aa, double tt) {
      return -nu * (1 + kDmu * std::cos(4 * (tt - th_mu))) * aa;
    };
    auto dth = [&](double tt) { return nu * kDmu * std::sin(4 * (tt - th_mu)) / 2; };
    while (a > floor) {
      const double a1 = da(a, th), t1 = dth(th);
      const double a2 = da(a + 0.5 * dt * a1, th + 0.5 * dt * t1), t2 = dth(th + 0.5 * dt * t1);
      const double a3 = da(a + 0.5 * dt * a2, th + 0.5 * dt * t2), t3 = dth(th + 0.5 * dt * t2);
      const double a4 = da(a + dt * a3, th + dt * t3), t4 = dth(th + dt * t3);
      a += dt * (a1 + 2 * a2 + 2 * a3 + a4) / 6;
      th += dt * (t1 + 2 * t2 + 2 * t3 + t4) / 6;
      t += dt;
    }
    const double closed = rundown_time_s(1.0, floor, nu, kDmu, th0, th_mu);
    std::printf("\n  from %.3f rad (th_mu 0.2): run-down %.1f s, integrated %.1f s", th0, closed,
                t);
    DOUBLES_EQUAL(t, closed, dt);
  }
  // On the axes: ln(a0 / floor) / (nu (1 +- dmu)).
  DOUBLES_EQUAL(std::log(1e4) / (nu * (1 + kDmu)),
                rundown_time_s(1.0, floor, nu, kDmu, th_mu, th_mu), 1e-6);
  DOUBLES_EQUAL(0.0, rundown_time_s(1e-5, floor, nu, kDmu, 0.0, 0.0), 0.0);
}
