// SPDX-License-Identifier: MIT
// The DC part of the pump's V^2 at resonances whose period is not a whole
// number of samples, and the pump it leaves: growth with no frequency pull.
#include <cmath>
#include <complex>
#include <cstdio>
#include <vector>

#include "sim_target/pump_dc_window.hpp"
#include "sim_target/resonator.hpp"

#include "support/cpputest.hpp"

using namespace hrg::sim;

namespace {

constexpr double kFs = 100000.0;
constexpr int kMaxLength = 255;

// V = v0 cos(psi0 + 2 pi n / P) squared, samples 0..n-1.
std::vector<double> pump_squares(double period, double v0, double psi0, int n) {
  std::vector<double> s(n);
  for (int k = 0; k < n; ++k) {
    const double v = v0 * std::cos(psi0 + 2.0 * kPi * k / period);
    s[k] = v * v;
  }
  return s;
}

}  // namespace

TEST_GROUP(PumpDcWindow){};

TEST(PumpDcWindow, TakesTheTwoFLineOutExactlyWhenThePeriodIsNotWhole) {
  // GIVEN a 3 V pump at resonances from 1.6 to 12 kHz (periods of 62.5 to
  // 8.33 samples at 100 kHz), four of them the ones the audit was run at
  for (double f_hz : {1600.0, 4200.0, 4900.0, 5100.0, 6000.0, 12000.0}) {
    const double period = kFs / f_hz;
    const PumpDcWindow w = pump_dc_window(period, kMaxLength);
    double worst_dc = 0.0;
    double worst_mean = 0.0;
    for (double psi0 : {0.0, 0.4, 1.3, 2.9}) {
      const auto s = pump_squares(period, 3.0, psi0, 200);
      for (int n = w.length + 4; n < 200; ++n) {
        double sum = 0.0;
        for (int j = 0; j < w.length; ++j)
          sum += s[n - j];
        const double mean = sum / w.length;
        // THEN the DC part is V0^2 / 2 at every sample, to rounding, while
        // the mean of the nearest whole number of samples leaks the line
        worst_dc = std::fmax(worst_dc, std::fabs(w.dc(sum, s[n], s[n - w.lag]) - 4.5));
        worst_mean = std::fmax(worst_mean, std::fabs(mean - 4.5));
      }
    }
    std::printf("\n  %.0f Hz (P %.3f, N %d, lag %d): DC error %.1e V^2, the mean's %.1e V^2", f_hz,
                period, w.length, w.lag, worst_dc, worst_mean);
    CHECK(worst_dc < 1e-12);
    CHECK(worst_mean > 0.03);
  }
  std::printf("\n");
}

TEST(PumpDcWindow, IsThePlainMeanToTheBitWhenThePeriodIsWhole) {
  // GIVEN 5 kHz at 100 kHz: 20 samples, whose mean has no 2f line
  const PumpDcWindow w = pump_dc_window(20.0, kMaxLength);
  LONGS_EQUAL(20, w.length);
  // THEN no correction: the DC part is the mean's bits, sum / 20
  CHECK(w.whole);
  const double sum = 89.999999999999986;
  CHECK(w.dc(sum, 8.7, 0.3) == sum / 20);
}

TEST(PumpDcWindow, ThePumpAtItsBestPhaseGrowsTheVibrationWithoutPullingItsFrequency) {
  // GIVEN an isotropic resonator at 4.2 and 6 kHz (default Q and pump gain),
  // ringing at 1 V, pumped open loop at 1.5 times its parametric threshold
  // with the pump a quarter turn of 2 phi ahead of the vibration (the chain's pi/4),
  // each held word phased at the middle of its step
  for (double f_hz : {4200.0, 6000.0}) {
    ResonatorParams rp;
    rp.f_hz = f_hz;
    rp.dmu = 0.0;
    rp.split_hz = 0.0;
    const ElectrodeParams ep;
    Resonator r(rp, ep);
    r.set_standing_wave(1.0, 0.0);
    const double w = rp.omega_rad_s();
    const double h = 1.0 / kFs;
    const double v0 = std::sqrt(1.5) * ep.threshold_v(w, rp.nu_per_s());
    const double t_s = 4.0;
    const long n = std::lround(t_s * kFs);
    for (long k = 0; k < n; ++k)
      r.step(Drive{v0 * std::cos(w * (static_cast<double>(k) + 0.5) * h + kPi / 4.0), 0.0, 0.0}, h);
    std::complex<double> x;
    std::complex<double> y;
    r.envelopes(x, y);
    const std::complex<double> env = x * std::polar(1.0, -w * r.time_s());
    // THEN the vibration grows at k V0^2 sinc(w h) / 8w - nu (the hold's loss of
    // the 2f line) and its phase does not move: the pull is below 1e-3 of the
    // pump's rate (it was 0.155 at 4.2 and 0.099 at 6 kHz with a 20-sample
    // DC window, 0.0039 to 0.0087 at 4.9 and 5.1 kHz)
    const double sinc = std::sin(w * h) / (w * h);
    const double g = ep.pump_gain_per_s2_v2 * v0 * v0 * sinc / (8.0 * w);
    const double growth = std::log(std::abs(env)) / t_s;
    const double pull = std::arg(env) / t_s;
    std::printf("\n  %.0f Hz: growth %.6e 1/s (predicted %.6e), pull %.1e of the pump's rate", f_hz,
                growth, g - rp.nu_per_s(), pull / g);
    DOUBLES_EQUAL(g - rp.nu_per_s(), growth, 1e-3 * g);
    CHECK(std::fabs(pull) < 1e-3 * g);
  }
  std::printf("\n");
}
