// SPDX-License-Identifier: MIT
// Averaged model against the closed-form rates of physics.md sections 1-2.
#include <cmath>

#include "free_decay_rates.hpp"
#include "sim_target/averaged_model.hpp"

#include "support/cpputest.hpp"

using namespace hrg::sim;

TEST_GROUP(AveragedModel){};

TEST(AveragedModel, FreeDecayRateFollowsDampingAnisotropyAtSeveralAngles) {
  ResonatorParams p;
  p.split_hz = 0.0;  // no quadrature build-up, so a_A decays at exactly its own rate
  p.th_mu_rad = 0.3;
  for (double theta : {0.0, 0.2, 0.5, 0.9, 1.3}) {
    AveragedModel m(p);
    m.set_standing_wave(1.0, theta);
    m.advance(10.0);
    const WaveState w = m.wave();
    const double rate = -std::log(w.a_A_v) / 10.0;
    const double expected = test::amplitude_decay_per_s(p, theta);
    DOUBLES_EQUAL(expected, rate, 1e-3 * expected);
  }
}

TEST(AveragedModel, QuadratureGrowsAtHalfSplitTimesSinFourTheta) {
  ResonatorParams p;
  p.dmu = 0.0;
  p.th_w_rad = 0.1;
  for (double theta : {0.3, 0.6, 1.0}) {
    AveragedModel m(p);
    m.set_standing_wave(1.0, theta);
    m.advance(0.5);
    const WaveState w = m.wave();
    const double rate = w.a_B_v / 0.5;  // a_B(0) = 0, a_A ~ 1
    const double expected = test::quadrature_growth_per_s(p, theta);
    DOUBLES_EQUAL(expected, rate, 1e-2 * std::abs(expected));
  }
}

TEST(AveragedModel, PrecessionIsMinusHalfAngularGainTimesRate) {
  ResonatorParams p;
  p.dmu = 0.0;
  p.split_hz = 0.0;
  AveragedModel m(p);
  const double rate = 100.0 * kDegToRad;
  m.set_rate_profile(Profile::constant(rate));
  m.set_standing_wave(1.0, 0.0);
  m.advance(0.01);
  const double expected = -p.angular_gain * rate / 2.0 * 0.01;
  DOUBLES_EQUAL(expected, m.wave().theta_rad, 1e-6 * std::abs(expected));
}

TEST(AveragedModel, DemodulatesAtAnotherReferenceByRotatingTheEnvelope) {
  // x = Re(X e^{i w t}) demodulated at f + 1 Hz turns by -2 pi (1 Hz) t: at t = 0.25 s by -90 deg.
  ResonatorParams p;
  p.q = 1e12;  // negligible decay
  p.dmu = 0.0;
  p.split_hz = 0.0;
  AveragedModel m(p);
  m.set_standing_wave(1.0, 0.0);
  m.advance(0.25);
  const Demodulated d = m.demodulated(p.f_hz + 1.0);
  // X' = X e^{-i pi/2} = -i: cx = 0, sx = +1
  DOUBLES_EQUAL(0.0, d.cx_v, 1e-9);
  DOUBLES_EQUAL(1.0, d.sx_v, 1e-8);
}

TEST(AveragedModel, AResonatorOffTheReferenceTurnsAtTheDifference) {
  ResonatorParams p;
  p.dmu = 0.0;
  p.split_hz = 0.0;
  AveragedModel m(p, {}, {}, p.f_hz + 0.2);
  m.set_standing_wave(1.0, 0.1);
  m.advance(1.0);
  DOUBLES_EQUAL(-2 * kPi * 0.2, m.wave().phase_a_rad, 1e-9);
}

TEST(AveragedModel, DriveFeedthroughAppearsOnlyWhileTheExcitationIsOn) {
  ResonatorParams p;
  Effects fx;
  fx.drive_feedthrough.enabled = true;
  fx.drive_feedthrough.x_v_per_v = 0.01;
  fx.drive_feedthrough.y_v_per_v = -0.004;
  fx.drive_feedthrough.x_phase_deg = 30.0;
  fx.drive_feedthrough.y_phase_deg = 0.0;
  DOUBLES_EQUAL(0.01, fx.drive_feedthrough.v_per_v(), 0.0);
  AveragedModel m(p, {}, fx);
  m.set_standing_wave(1.0, 0.0);
  const Demodulated off = m.demodulated();
  EnvelopeDrive d;
  d.excitation = true;
  d.pump_v = 3.0;
  d.pump_phase_rad = kPi / 4;  // relative to the wave, whose phase is 0 now
  m.set_drive(d);
  const Demodulated on = m.demodulated();
  // X jumps by c V0 e^{i(pi/4 + 30 deg)}; X = cx - i sx.
  const double ph = kPi / 4 + 30.0 * kDegToRad;
  DOUBLES_EQUAL(0.01 * 3.0 * std::cos(ph), on.cx_v - off.cx_v, 1e-12);
  DOUBLES_EQUAL(-0.01 * 3.0 * std::sin(ph), on.sx_v - off.sx_v, 1e-12);
  DOUBLES_EQUAL(-0.004 * 3.0 * std::cos(kPi / 4), on.cy_v - off.cy_v, 1e-12);
}

TEST(AveragedModel, MisalignedYPickoffSeesSinTwoBetaOfX) {
  Effects fx;
  fx.pickoff_misalignment.enabled = true;
  fx.pickoff_misalignment.angle_deg = 1.0;
  AveragedModel m({}, {}, fx);
  m.set_standing_wave(1.0, 0.0);  // pure x
  const Demodulated d = m.demodulated();
  DOUBLES_EQUAL(1.0, d.cx_v, 1e-12);
  DOUBLES_EQUAL(std::sin(2.0 * kDegToRad), d.cy_v, 1e-12);
}

TEST(AveragedModel, NonlinearDampingScalesTheDecayWithEnergy) {
  ResonatorParams p;
  p.dmu = 0.0;
  p.split_hz = 0.0;
  Effects fx;
  fx.nonlinear_damping.enabled = true;
  fx.nonlinear_damping.rel_per_v2 = 0.1;
  AveragedModel m(p, {}, fx);
  m.set_standing_wave(2.0, 0.0);
  m.advance(0.01);
  const double rate = -std::log(m.wave().a_A_v / 2.0) / 0.01;
  DOUBLES_EQUAL(p.nu_per_s() * (1.0 + 0.1 * 4.0), rate, 1e-4 * rate);
}

TEST(AveragedModel, RateStepsAreAppliedAtTheirExactTimes) {
  // GIVEN an isotropic resonator and a rate step of 10 deg/s at t = 0.0123 s
  ResonatorParams p;
  p.dmu = 0.0;
  p.split_hz = 0.0;
  AveragedModel m(p);
  const double rate = 10.0 * kDegToRad;
  m.set_rate_profile(Profile::steps({{0.0, 0.0}, {0.0123, rate}}));
  m.set_standing_wave(1.0, 0.0);
  // WHEN advanced in 10 ms outputs (the step falls inside the second one)
  for (int i = 0; i < 5; ++i)
    m.advance(0.01);
  // THEN the angle is -K Omega/2 times the exact time since the step
  DOUBLES_EQUAL(-p.angular_gain * rate / 2.0 * (0.05 - 0.0123), m.wave().theta_rad, 1e-12);
}
