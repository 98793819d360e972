// SPDX-License-Identifier: MIT
#include "dsp/wave_variables.hpp"

#include <cmath>
#include <complex>
#include <numbers>

#include "support/cpputest.hpp"

using hrg::dsp::Quadratures;
using hrg::dsp::quadratures_of_wave;
using hrg::dsp::ThetaUnwrapper;
using hrg::dsp::wave_variables;

namespace {
constexpr double kPi = std::numbers::pi;

// Quadratures straight from the definition x = Re(X e^{iwt}): sample the
// pattern over one period and project on cos and sin of the reference.
Quadratures<double> demodulate_by_definition(double a_A, double a_B, double th, double phi) {
  constexpr int kN = 4096;
  Quadratures<double> q;
  for (int k = 0; k < kN; ++k) {
    const double wt = 2.0 * kPi * k / kN;
    const double x =
        a_A * std::cos(2 * th) * std::cos(wt + phi) - a_B * std::sin(2 * th) * std::sin(wt + phi);
    const double y =
        a_A * std::sin(2 * th) * std::cos(wt + phi) + a_B * std::cos(2 * th) * std::sin(wt + phi);
    q.cx += 2.0 * x * std::cos(wt) / kN;
    q.sx += 2.0 * x * std::sin(wt) / kN;
    q.cy += 2.0 * y * std::cos(wt) / kN;
    q.sy += 2.0 * y * std::sin(wt) / kN;
  }
  return q;
}
}  // namespace

TEST_GROUP(WaveVariables){};

TEST(WaveVariables, RecoverAmplitudesAngleAndPhaseOfAnySampledPattern) {
  // GIVEN patterns over a grid of angles, phases and quadrature ratios
  for (double th = -0.78; th < 0.78; th += 0.13) {
    for (double phi = -1.5; phi < 1.5; phi += 0.37) {
      for (double ratio : {0.0, 0.05, -0.2}) {
        const double a_A = 0.3, a_B = ratio * a_A;
        // WHEN the quadratures come from sampling and projecting the pickoffs
        const auto w = wave_variables(demodulate_by_definition(a_A, a_B, th, phi));
        // THEN the physics.md identities hold
        DOUBLES_EQUAL(a_A * a_A + a_B * a_B, w.E_v2, 1e-12);
        DOUBLES_EQUAL(2 * a_A * a_B, w.Q_v2, 1e-12);
        DOUBLES_EQUAL((a_A * a_A - a_B * a_B) * std::cos(4 * th), w.R_v2, 1e-12);
        DOUBLES_EQUAL((a_A * a_A - a_B * a_B) * std::sin(4 * th), w.S_v2, 1e-12);
        DOUBLES_EQUAL(a_A, w.a_A_v, 1e-12);
        DOUBLES_EQUAL(a_B, w.a_B_v, 1e-12);
        DOUBLES_EQUAL(th, w.theta_A_rad, 1e-12);
        DOUBLES_EQUAL(phi, w.phase_rad, 1e-12);
        DOUBLES_EQUAL(w.E_v2 * w.E_v2, w.R_v2 * w.R_v2 + w.S_v2 * w.S_v2 + w.Q_v2 * w.Q_v2, 1e-12);
      }
    }
  }
}

TEST(WaveVariables, InverseMatchesTheSampledDefinition) {
  const auto a = quadratures_of_wave(0.7, -0.03, 0.4, 0.9);
  const auto b = demodulate_by_definition(0.7, -0.03, 0.4, 0.9);
  DOUBLES_EQUAL(b.cx, a.cx, 1e-13);
  DOUBLES_EQUAL(b.sx, a.sx, 1e-13);
  DOUBLES_EQUAL(b.cy, a.cy, 1e-13);
  DOUBLES_EQUAL(b.sy, a.sy, 1e-13);
}

TEST(WaveVariables, EnvelopesMapToQuadraturesAsPhysicsMdDefines) {
  // x = Re(X e^{iwt}) with X = cx - i sx: x = cx cos wt + sx sin wt
  const std::complex<double> x_env(0.3, -0.4), y_env(-0.1, 0.2);
  const auto q = hrg::dsp::quadratures_of_envelopes(x_env, y_env);
  for (double wt : {0.0, 0.7, 2.0, 4.4}) {
    const std::complex<double> e(std::cos(wt), std::sin(wt));
    DOUBLES_EQUAL((x_env * e).real(), q.cx * std::cos(wt) + q.sx * std::sin(wt), 1e-15);
    DOUBLES_EQUAL((y_env * e).real(), q.cy * std::cos(wt) + q.sy * std::sin(wt), 1e-15);
  }
}

TEST(WaveVariables, SmallQuadratureKeepsRelativePrecisionInFloat) {
  // a_B = 1e-6 a_A: sqrt(E - N) would lose it all in float (error ~ sqrt(eps) a_A
  // = 2e-4 a_A); Q / 2a_A is limited by the rounding of the inputs (~eps a_A).
  const auto q = quadratures_of_wave(0.5, 0.5e-6, 0.3, 0.2);
  const Quadratures<float> qf{static_cast<float>(q.cx), static_cast<float>(q.sx),
                              static_cast<float>(q.cy), static_cast<float>(q.sy)};
  const auto w = wave_variables(qf);
  DOUBLES_EQUAL(0.5e-6, w.a_B_v, 0.5 * 6e-8);
  DOUBLES_EQUAL(0.3, w.theta_A_rad, 1e-6);
}

TEST(WaveVariables, ZeroAmplitudeGivesZeroNotNan) {
  const auto w = wave_variables(Quadratures<double>{});
  CHECK_EQUAL(0.0, w.a_A_v);
  CHECK_EQUAL(0.0, w.theta_A_rad);
  CHECK_EQUAL(0.0, w.phase_rad);
}

TEST_GROUP(ThetaUnwrapper){};

TEST(ThetaUnwrapper, FollowsManyTurnsInBothDirections) {
  ThetaUnwrapper<float> u;
  ThetaUnwrapper<double> ud;
  // GIVEN a pattern turning at 100 deg/s for 60 s sampled at 1 kHz, then back
  const double rate = 100.0 * kPi / 180.0;
  double th = 0.1;
  for (int k = 0; k < 120000; ++k) {
    th += (k < 60000 ? rate : -1.5 * rate) * 1e-3;
    const auto q = quadratures_of_wave(1.0, 0.0, th, 0.0);
    const auto wd = wave_variables(q);
    ud.update(wd.theta_A_rad);
    u.update(static_cast<float>(wd.theta_A_rad));
    // THEN the unwrapped angle equals the true one at every step
    DOUBLES_EQUAL(th, ud.value(), 1e-9);
    DOUBLES_EQUAL(th, u.value_f64(), 1e-6);
  }
  // 60 s * 100 deg/s forward then 60 s * 150 deg/s back = -3000 deg net
  DOUBLES_EQUAL(0.1 - 3000.0 * kPi / 180.0, ud.value(), 1e-8);
  CHECK(ud.quarter_turns() < -30);
}

TEST(ThetaUnwrapper, ResetStartsFromTheWrappedValue) {
  ThetaUnwrapper<double> u;
  u.update(0.7);
  u.update(-0.7);  // crossed +pi/4 upward
  DOUBLES_EQUAL(-0.7 + kPi / 2, u.value(), 1e-15);
  u.reset();
  DOUBLES_EQUAL(-0.7, u.update(-0.7), 0.0);
}
