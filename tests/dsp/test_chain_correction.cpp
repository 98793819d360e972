// SPDX-License-Identifier: MIT
// The chain's electronics-correction stage: a standing wave seen through a
// mismatched y pickoff (gain, phase lag, misalignment) reads the pattern
// angle wrongly by up to about g/4 rad (the 4 theta readout error); with the
// map's inverse in the chain the wave variables are those of the true wave.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "dsp/chain.hpp"
#include "dsp/pickoff_correction.hpp"
#include "support/cpputest.hpp"

using namespace hrg::dsp;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// One ADC block of a standing wave at the chain's own NCO (amplitude a_v,
// pattern angle theta), x ideal, y through the map; volts -> Q1.31.
template <typename T>
void wave_block(const Chain<T>& chain, const PickoffMap& map, double a_v, double theta_rad,
                std::vector<q31_t>& adc) {
  const ChainConfig& c = chain.config();
  uint32_t psi = chain.nco_phase();
  const double g = 1.0 + map.y_gain;
  const double c2b = std::cos(2.0 * map.y_misalignment_rad);
  const double s2b = std::sin(2.0 * map.y_misalignment_rad);
  for (uint32_t j = 0; j < c.block_frames; ++j) {
    const double wt = 2.0 * kPi * (static_cast<double>(psi) / 4294967296.0);
    const double x = a_v * std::cos(2.0 * theta_rad) * std::cos(wt);
    const double y_lag = a_v * std::sin(2.0 * theta_rad) * std::cos(wt - map.y_phase_rad);
    const double x_lag = a_v * std::cos(2.0 * theta_rad) * std::cos(wt - map.y_phase_rad);
    adc[2 * j] = q31_from_f64_sat(x / c.adc_full_scale_v);
    adc[2 * j + 1] = q31_from_f64_sat(g * (c2b * y_lag + s2b * x_lag) / c.adc_full_scale_v);
    psi += chain.nco_step();
  }
}

// Largest |theta_read - theta| (rad) over 24 pattern angles, 6 blocks each
// (the decimator's three-block memory filled with the new angle).
template <typename T>
double worst_angle_error_rad(const PickoffMap& map, bool corrected) {
  ChainConfig cfg;
  Chain<T> chain(cfg);
  if (corrected) {
    PickoffCorrection<double> k;
    CHECK_TRUE(pickoff_correction_of(map, k));
    CHECK_TRUE(chain.set_electronics_correction(k, {}));
  }
  std::vector<q31_t> adc(2 * cfg.block_frames);
  std::vector<q31_t> dac(3 * cfg.block_frames);
  double worst = 0.0;
  for (int i = 0; i < 24; ++i) {
    const double theta = (i + 0.37) * kPi / 48.0;  // 0..90 deg: one 4 theta turn
    for (int n = 0; n < 6; ++n) {
      wave_block(chain, map, 1.0, theta, adc);
      CHECK_TRUE(chain.process(adc, dac));
    }
    const double read = chain.outputs().wave.theta_A_rad;
    worst = std::max(worst, std::fabs(std::remainder(read - theta, kPi / 2.0)));
  }
  return worst;
}

}  // namespace

TEST_GROUP(ChainCorrection){};

TEST(ChainCorrection, PickoffGainMismatchReadoutErrorIsRemovedInQ31AndDouble) {
  const PickoffMap map{0.01, 0.0, 0.0};
  // theta_read = atan((1+g) tan 2theta)/2: worst g/4 rad (first order).
  const double expected = 0.5 * std::atan((1.0 + 0.01) * 1.0) - kPi / 8.0;
  DOUBLES_EQUAL(expected, worst_angle_error_rad<q31_t>(map, false), 0.05 * expected);
  DOUBLES_EQUAL(expected, worst_angle_error_rad<double>(map, false), 0.05 * expected);
  CHECK_TRUE(worst_angle_error_rad<q31_t>(map, true) < 1e-6);
  CHECK_TRUE(worst_angle_error_rad<double>(map, true) < 1e-6);
}

TEST(ChainCorrection, FullPickoffMapIsInvertedInTheChain) {
  // 1 % gain, 1 deg lag, 0.5 deg misalignment: uncorrected the pattern reads
  // off by about b (0.5 deg) plus g/4; corrected, by less than 1e-6 rad.
  const PickoffMap map{0.01, 1.0 * kDeg, 0.5 * kDeg};
  CHECK_TRUE(worst_angle_error_rad<q31_t>(map, false) > 0.4 * kDeg);
  CHECK_TRUE(worst_angle_error_rad<q31_t>(map, true) < 1e-6);
  CHECK_TRUE(worst_angle_error_rad<float>(map, true) < 2e-5);
  CHECK_TRUE(worst_angle_error_rad<double>(map, true) < 1e-6);
}

TEST(ChainCorrection, IdentityByDefaultAndClearable) {
  ChainConfig cfg;
  Chain<q31_t> chain(cfg);
  CHECK_FALSE(chain.electronics_correction().active());
  PickoffCorrection<double> k;
  CHECK_TRUE(pickoff_correction_of({0.01, 0.0, 0.0}, k));
  CHECK_TRUE(chain.set_electronics_correction(k, {}));
  CHECK_TRUE(chain.electronics_correction().active());
  // A feedthrough that does not fit Q1.31 (2.5 ADC full scale per DAC full scale) is refused
  // whole.
  CHECK_FALSE(chain.set_electronics_correction(k, {0.5, 0.0, 0.0, 0.0}));
  chain.clear_electronics_correction();
  CHECK_FALSE(chain.electronics_correction().active());
}
