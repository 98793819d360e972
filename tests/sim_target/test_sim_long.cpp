// SPDX-License-Identifier: MIT
// Long checks (label slow): full-rate and averaged models agree over 600 s;
// the ramp path gives the per-sample path's bits over an hour.
#include <array>
#include <cmath>
#include <vector>

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

TEST(LongRun, StepBlockGivesTheBitsOfStepByStepOverOneHourOfRamps) {
  // GIVEN the seed resonator on a rate table that ramps back and forth
  // between 0 and 0.5 rad/s every second for an hour (every step on a ramp,
  // a re-expansion every 0.1 s, a corner every 100 000 steps), pumped and
  // forced
  ResonatorParams p;
  p.th_mu_rad = 0.2;
  p.th_w_rad = 0.5;
  std::vector<ProfilePoint> triangle;
  for (int i = 0; i <= 3600; ++i)
    triangle.push_back({static_cast<double>(i), 0.5 * (i % 2)});
  Resonator a(p);
  a.set_rate_profile(Profile::ramps(triangle));
  a.set_state(0.83, 0.56, -1.9e3, 2.7e3);  // both pickoffs, in and out of phase
  Resonator b = a;
  std::array<Drive, 100> drives{};
  for (std::size_t k = 0; k < drives.size(); ++k) {
    const double ph = 2.0 * kPi * p.f_hz * static_cast<double>(k) * 1e-5;
    drives[k] = {3.0 * std::cos(2.0 * ph), 0.01 * std::sin(ph), -0.01 * std::cos(ph)};
  }
  // WHEN one runs in blocks of 100 steps (the ramp path) and the other step
  // by step (the rate, the propagator and the product evaluated per sample)
  std::array<PickoffOutput, 100> got{};
  long mismatches = 0;
  for (long block = 0; block < 3'600'000; ++block) {
    b.step_block(drives.data(), drives.size(), 1e-5,
                 [&got](std::size_t k, const PickoffOutput& out) { got[k] = out; });
    for (std::size_t k = 0; k < drives.size(); ++k) {
      const PickoffOutput want = a.measured();
      mismatches += (want.x_v != got[k].x_v) + (want.y_v != got[k].y_v);
      a.step(drives[k], 1e-5);
    }
  }
  // THEN every pickoff sample and the end state are the same to the bit
  LONGS_EQUAL(0, mismatches);
  CHECK_EQUAL(a.x_v(), b.x_v());
  CHECK_EQUAL(a.y_v(), b.y_v());
  CHECK_EQUAL(a.vx_v_per_s(), b.vx_v_per_s());
  CHECK_EQUAL(a.vy_v_per_s(), b.vy_v_per_s());
  DOUBLES_EQUAL(3600.0, b.time_s(), 1e-9);
}
