// SPDX-License-Identifier: MIT
// Full-rate resonator against the closed-form rates of physics.md and against
// the averaged model.
#include <cmath>
#include <array>
#include <complex>
#include <utility>

#include "free_decay_rates.hpp"
#include "sim_target/averaged_model.hpp"
#include "sim_target/resonator.hpp"

#include "support/cpputest.hpp"

using namespace hrg::sim;

namespace {

constexpr double kDt = 1e-5;  // fs = 100 kHz

WaveState true_wave(const Resonator& r) {
  cplx x;
  cplx y;
  r.envelopes(x, y);
  return wave_state(x, y);
}

void ring(Resonator& r, double t_s, const Drive& d = {}) {
  const long n = std::lround(t_s / kDt);
  for (long i = 0; i < n; ++i)
    r.step(d, kDt);
}

// Envelope phase of x relative to the carrier e^{i w t} of the nominal frequency.
double envelope_phase(const Resonator& r, double w, bool of_y) {
  cplx x;
  cplx y;
  r.envelopes(x, y);
  return std::arg((of_y ? y : x) * std::polar(1.0, -w * r.time_s()));
}

}  // namespace

TEST_GROUP(Resonator){};

TEST(Resonator, FreeDecayRateFollowsDampingAnisotropyAtSeveralAngles) {
  // GIVEN the seed's resonator without split (so that a_B stays zero)
  ResonatorParams p;
  p.split_hz = 0.0;
  p.th_mu_rad = 0.3;
  for (double theta : {0.0, 0.25, 0.6, 1.1}) {
    Resonator r(p);
    r.set_standing_wave(1.0, theta);
    // WHEN it rings down freely for 2 s
    ring(r, 2.0);
    // THEN a_A decays at nu (1 + dmu cos 4(theta - th_mu)) within 0.1 %
    const double rate = -std::log(true_wave(r).a_A_v) / 2.0;
    const double expected = test::amplitude_decay_per_s(p, theta);
    DOUBLES_EQUAL(expected, rate, 1e-3 * expected);
  }
}

TEST(Resonator, QuadratureGrowsAtHalfSplitTimesSinFourTheta) {
  ResonatorParams p;
  p.dmu = 0.0;
  p.th_w_rad = 0.1;
  for (double theta : {0.3, 0.7, 1.2}) {
    Resonator r(p);
    r.set_standing_wave(1.0, theta);
    ring(r, 0.5);
    const WaveState w = true_wave(r);
    // a_B' = dw sin4(theta - th_w) a_A with dw = pi split (half split, rad/s)
    const double expected = test::quadrature_growth_per_s(p, theta) * 0.5 * (1.0 + w.a_A_v) * 0.5;
    DOUBLES_EQUAL(expected, w.a_B_v, 1e-2 * std::abs(expected));
  }
}

TEST(Resonator, PrecessionIsMinusHalfAngularGainTimesRate) {
  ResonatorParams p;
  p.dmu = 0.0;
  p.split_hz = 0.0;
  Resonator r(p);
  const double rate = 100.0 * kDegToRad;
  r.set_rate_profile(Profile::constant(rate));
  r.set_standing_wave(1.0, 0.0);
  // Track the unwrapped angle over 1 s (theta_A is defined modulo pi/2).
  double theta = 0.0;
  double last = 0.0;
  for (int k = 0; k < 100; ++k) {
    ring(r, 0.01);
    const double now = true_wave(r).theta_rad;
    theta += std::remainder(now - last, kPi / 2.0);
    last = now;
  }
  const double expected = -p.angular_gain * rate / 2.0 * r.time_s();
  DOUBLES_EQUAL(expected, theta, 1e-6 * std::abs(expected));
}

TEST(Resonator, TheTwoModesRingAtMeanPlusAndMinusHalfSplit) {
  // A 1 Hz split so that the beat shows in 2 s at full rate; stiff axis along x.
  ResonatorParams p;
  p.dmu = 0.0;
  p.split_hz = 1.0;
  Resonator r(p);
  r.set_standing_wave(1.0, kPi / 8.0);  // off-axis: both modes excited equally
  const double w = p.omega_rad_s();
  const double px0 = envelope_phase(r, w, false);
  const double py0 = envelope_phase(r, w, true);
  ring(r, 0.4);
  const double fx = std::remainder(envelope_phase(r, w, false) - px0, 2 * kPi) / (2 * kPi * 0.4);
  const double fy = std::remainder(envelope_phase(r, w, true) - py0, 2 * kPi) / (2 * kPi * 0.4);
  DOUBLES_EQUAL(+0.5 * p.split_hz, fx, 1e-3 * p.split_hz);
  DOUBLES_EQUAL(-0.5 * p.split_hz, fy, 1e-3 * p.split_hz);
}

TEST(Resonator, AgreesWithTheAveragedModelOverTenSecondsWithRotation) {
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
  ring(r, 10.0);
  m.advance(10.0);
  const WaveState wr = true_wave(r);
  const WaveState wa = m.wave();
  DOUBLES_EQUAL(0.0, std::remainder(wr.theta_rad - wa.theta_rad, kPi / 2), 1e-5);
  DOUBLES_EQUAL(wa.a_A_v, wr.a_A_v, 1e-6 * wa.a_A_v);
}

TEST(Resonator, AgreesWithTheAveragedModelUnderASineRateAndATemperatureRamp) {
  // GIVEN time-varying inputs, which exercise the propagator sensitivities and
  // the moving expansion point: 200 deg/s at 2 Hz and a 10 degC ramp at -50 ppm/degC
  ResonatorParams p;
  p.th_mu_rad = 0.2;
  p.th_w_rad = 0.5;
  Effects fx;
  fx.thermal_frequency.enabled = true;
  fx.thermal_frequency.ppm_per_c = -50.0;
  fx.thermal_damping.enabled = true;
  fx.thermal_damping.rel_per_c = 0.01;
  const Profile rate = Profile::sine(200.0 * kDegToRad, 2.0, 0.3);
  const Profile temp = Profile::ramps({{0.0, 25.0}, {1.5, 35.0}});
  Resonator r(p, {}, fx);
  AveragedModel m(p, {}, fx);
  r.set_rate_profile(rate);
  m.set_rate_profile(rate);
  r.set_temperature_profile(temp);
  m.set_temperature_profile(temp);
  m.set_max_step_s(1e-3);
  r.set_standing_wave(1.0, 0.3);
  m.set_standing_wave(1.0, 0.3);
  // WHEN both run 1.5 s
  ring(r, 1.5);
  // The instantaneous x - i x'/w differs from the envelope by O(Omega K / w) at 2w
  // (a few 1e-6 rad here): average the full-rate angle over one carrier period
  // (samples 1..20 after 1.5 s, mean time 1.5 s + 10.5 h).
  double theta_sum = 0.0;
  double last = true_wave(r).theta_rad;
  double theta_unwrapped = last;
  for (int n = 0; n < 20; ++n) {
    r.step({}, kDt);
    const double now = true_wave(r).theta_rad;
    theta_unwrapped += std::remainder(now - last, kPi / 2);
    last = now;
    theta_sum += theta_unwrapped;
  }
  m.advance(1.5 + 10.5 * kDt);
  const WaveState wa = m.wave();
  DOUBLES_EQUAL(0.0, std::remainder(theta_sum / 20.0 - wa.theta_rad, kPi / 2), 2e-7);
  m.advance(9.5 * kDt);  // now at the same time as the full-rate model
  const WaveState wr = true_wave(r);
  DOUBLES_EQUAL(m.wave().a_A_v, wr.a_A_v, 1e-6);
  const double w0 = p.omega_rad_s();
  cplx x;
  cplx y;
  r.envelopes(x, y);
  const double phase_full =
      std::arg((x * std::cos(2 * wr.theta_rad) + y * std::sin(2 * wr.theta_rad)) *
               std::polar(1.0, -w0 * r.time_s()));
  DOUBLES_EQUAL(0.0, std::remainder(phase_full - m.wave().phase_a_rad, 2 * kPi), 1e-5);
}

// step_block against step() one sample at a time, every output and the end
// state to the bit, on a hold of the rate (the held-inputs paths).
void check_block_against_steps(Resonator a) {
  Resonator b = a;
  std::array<Drive, 100> drives{};
  std::array<PickoffOutput, 100> got{};
  for (int block = 0; block < 10; ++block) {
    for (std::size_t k = 0; k < drives.size(); ++k) {
      const double t = (block * 100.0 + static_cast<double>(k)) * kDt;
      drives[k] = {2.0 + std::cos(4e4 * t), 0.01 * std::sin(3e4 * t), -0.02 * std::cos(2e4 * t)};
    }
    b.step_block(drives.data(), drives.size(), kDt,
                 [&got](std::size_t k, const PickoffOutput& out) { got[k] = out; });
    for (std::size_t k = 0; k < drives.size(); ++k) {
      const PickoffOutput want = a.measured();
      CHECK_EQUAL(want.x_v, got[k].x_v);
      CHECK_EQUAL(want.y_v, got[k].y_v);
      a.step(drives[k], kDt);
    }
  }
  CHECK_EQUAL(a.x_v(), b.x_v());
  CHECK_EQUAL(a.y_v(), b.y_v());
  CHECK_EQUAL(a.vx_v_per_s(), b.vx_v_per_s());
  CHECK_EQUAL(a.vy_v_per_s(), b.vy_v_per_s());
  CHECK_EQUAL(a.time_s(), b.time_s());
}

TEST(Resonator, StepBlockGivesTheBitsOfStepByStepOnEveryHeldPath) {
  // Plain (the loop on pairs of rows: pump, spring, both forcers), with a
  // pickoff effect, and with a thermal stiffness and damping change (the
  // general loop).
  ResonatorParams p;
  Effects plain;
  plain.electrostatic_spring.enabled = true;
  Effects pickoff;
  pickoff.pickoff_phase_mismatch = {true, 0.5};
  Effects thermal;
  thermal.thermal_frequency = {true, -50.0};
  thermal.thermal_damping = {true, 0.01};
  for (const Effects& fx : {plain, pickoff, thermal}) {
    Resonator r(p, ElectrodeParams{}, fx);
    r.set_rate_profile(Profile::constant(0.1));
    r.set_temperature_profile(Profile::constant(p.temp_ref_c + 3.0));
    r.set_standing_wave(1.0, 0.3, 0.01);
    check_block_against_steps(r);
  }
}

TEST(Resonator, StepBlockGivesTheBitsOfStepByStepWhileTheRateRamps) {
  // The ramp path (each step's propagator formed in registers): a rise at
  // 50 rad/s^2 (a re-expansion every 100 steps, inside the blocks), a flat
  // piece, a fall at 250 rad/s^2 (one every 20 steps), corners inside the
  // blocks, then a hold. Plain with the spring, and with a thermal
  // stiffness at a held temperature (both take the ramp path); with a
  // pickoff effect, with a thermal damping change (declined once the step is
  // prepared) and under a temperature ramp (all declined: step() per step).
  ResonatorParams p;
  p.th_mu_rad = 0.2;
  p.th_w_rad = 0.5;
  Effects spring;
  spring.electrostatic_spring.enabled = true;
  Effects thermal;
  thermal.thermal_frequency = {true, -50.0};
  Effects pickoff;
  pickoff.pickoff_phase_mismatch = {true, 0.5};
  Effects damping;
  damping.thermal_damping = {true, 0.01};
  const Profile rate =
      Profile::ramps({{0.00037, 0.1}, {0.00437, 0.3}, {0.00611, 0.3}, {0.00813, -0.2}});
  const Profile held = Profile::constant(p.temp_ref_c + 3.0);
  const Profile warming = Profile::ramps({{0.0, p.temp_ref_c}, {0.01, p.temp_ref_c + 1.0}});
  const std::array<std::pair<Effects, const Profile*>, 5> cases{
      {{spring, &held}, {thermal, &held}, {pickoff, &held}, {damping, &held}, {thermal, &warming}}};
  for (const auto& [fx, temp] : cases) {
    Resonator r(p, ElectrodeParams{}, fx);
    r.set_rate_profile(rate);
    r.set_temperature_profile(*temp);
    r.set_state(0.83, 0.56, -1.9e3, 2.7e3);  // both pickoffs, in and out of phase
    check_block_against_steps(r);
  }
}

TEST(Resonator, StepBlockGivesTheBitsOfStepByStep) {
  // A rate step inside the blocks (per-step path) and holds between them
  // (held-inputs path), with the pump and the forcers driven.
  ResonatorParams p;
  Resonator a(p);
  a.set_rate_profile(Profile::steps({{0.0, 0.1}, {0.0123, -0.2}}));
  a.set_standing_wave(1.0, 0.3, 0.01);
  Resonator b = a;
  std::array<Drive, 100> drives{};
  std::array<PickoffOutput, 100> got{};
  for (int block = 0; block < 30; ++block) {
    for (std::size_t k = 0; k < drives.size(); ++k) {
      const double t = (block * 100.0 + static_cast<double>(k)) * kDt;
      drives[k] = {2.0 + std::cos(4e4 * t), 0.01 * std::sin(3e4 * t), 0.0};
    }
    b.step_block(drives.data(), drives.size(), kDt,
                 [&got](std::size_t k, const PickoffOutput& out) { got[k] = out; });
    for (std::size_t k = 0; k < drives.size(); ++k) {
      const PickoffOutput want = a.measured();
      CHECK_EQUAL(want.x_v, got[k].x_v);
      CHECK_EQUAL(want.y_v, got[k].y_v);
      a.step(drives[k], kDt);
    }
  }
  CHECK_EQUAL(a.x_v(), b.x_v());
  CHECK_EQUAL(a.vy_v_per_s(), b.vy_v_per_s());
  CHECK_EQUAL(a.time_s(), b.time_s());
}
