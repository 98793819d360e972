// SPDX-License-Identifier: MIT
// Long check (label slow): full-rate and averaged models agree over 600 s.
#include <cmath>

#include "sim_target/averaged_model.hpp"
#include "sim_target/resonator.hpp"

#include "support/cpputest.hpp"

using namespace hrg::sim;

TEST_GROUP(LongRun){};

TEST(LongRun, FullRateAndAveragedAgreeOverSixHundredSecondsWithRotation) {
  // GIVEN the default (seed) resonator with its axes off the pickoffs, rotating at 100 deg/s
  ResonatorParams p;
  p.th_mu_rad = 0.2;
  p.th_w_rad = 0.5;
  const double rate = 100.0 * kDegToRad;
  Resonator r(p);
  AveragedModel m(p);
  r.set_rate_profile(Profile::constant(rate));
  m.set_rate_profile(Profile::constant(rate));
  r.set_standing_wave(1.0, 0.3);
  m.set_standing_wave(1.0, 0.3);
  // WHEN both ring down for 600 s (60 M samples at 100 kHz)
  double worst_angle = 0.0;
  double worst_amp = 0.0;
  for (int k = 0; k < 60; ++k) {
    for (int i = 0; i < 1'000'000; ++i)
      r.step({}, 1e-5);
    m.advance(10.0);
    cplx x;
    cplx y;
    r.envelopes(x, y);
    const WaveState wr = wave_state(x, y);
    const WaveState wa = m.wave();
    worst_angle =
        std::max(worst_angle, std::abs(std::remainder(wr.theta_rad - wa.theta_rad, kPi / 2)));
    worst_amp = std::max(worst_amp, std::abs(wr.a_A_v / wa.a_A_v - 1.0));
  }
  // THEN the angle agrees within 1e-4 rad and the amplitude within 1e-5 relative
  DOUBLES_EQUAL(0.0, worst_angle, 1e-4);
  DOUBLES_EQUAL(0.0, worst_amp, 1e-5);
}

TEST(LongRun, FullRateMatchesTheExactDampedOscillatorAfterSixHundredSeconds) {
  // GIVEN an isotropic damped oscillator released from rest along theta = 0.3
  ResonatorParams p;
  p.dmu = 0.0;
  p.split_hz = 0.0;
  Resonator r(p);
  r.set_standing_wave(1.0, 0.3);
  // WHEN it runs 60 M samples (600 s at 100 kHz)
  for (long i = 0; i < 60'000'000; ++i)
    r.step({}, 1e-5);
  // THEN x(t) = x0 e^{-nu t}(cos wd t + nu/wd sin wd t), wd = sqrt(w^2 - nu^2), within
  // 1e-6 of the amplitude (the propagator is exact; only rounding accumulates)
  const double w = p.omega_rad_s();
  const double nu = p.nu_per_s();
  const double wd = std::sqrt(w * w - nu * nu);
  const double t = r.time_s();
  DOUBLES_EQUAL(600.0, t, 1e-9);
  const double x0 = std::cos(0.6);
  const double amp = x0 * std::exp(-nu * t);
  const double x_exact = amp * (std::cos(wd * t) + nu / wd * std::sin(wd * t));
  const double v_exact = -amp * (w * w / wd) * std::sin(wd * t);
  DOUBLES_EQUAL(x_exact, r.x_v(), 1e-6 * amp);
  DOUBLES_EQUAL(v_exact / w, r.vx_v_per_s() / w, 1e-6 * amp);
}
