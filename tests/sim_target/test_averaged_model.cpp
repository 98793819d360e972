// SPDX-License-Identifier: MIT
// Averaged model against the closed-form rates of physics.md sections 1-2.
#include <cmath>

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
    const double rate = -std::log(w.a_a_v) / 10.0;
    const double expected = p.nu_per_s() * (1.0 + p.dmu * std::cos(4.0 * (theta - p.th_mu_rad)));
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
    const double rate = w.a_b_v / 0.5;  // a_B(0) = 0, a_A ~ 1
    const double expected = p.half_split_rad_s() * std::sin(4.0 * (theta - p.th_w_rad));
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
