// SPDX-License-Identifier: MIT
#pragma once

#include <span>
#include <string>
#include <vector>

#include "characterize/harmonic_fit.hpp"

namespace hrg::characterize {

// One rate-table step of an IEEE 1431 scale-factor series: the table's input
// rate and the gyro's mean output rate over whole turns at it.
struct RateStep {
  double input_rad_s = 0.0;
  double output_rad_s = 0.0;
  double sigma_rad_s = 0.0;  // standard error of output_rad_s; 0: unknown
};

// Scale factor K (output per input; 1 for an ideal whole-angle readout),
// straight line output = bias + K input fitted by least squares (weighted
// by 1/sigma^2 when every step states its sigma; otherwise sigma is taken
// from the residuals). Uncertainties are 1 sigma.
struct ScaleFactorSeries {
  double k = 0.0, sigma_k = 0.0;
  double k_error_ppm = 0.0, sigma_k_error_ppm = 0.0;  // (K - K_nominal) / K_nominal
  double bias_rad_s = 0.0, sigma_bias_rad_s = 0.0;
  // Nonlinearity: the largest |deviation| of a step from the straight line,
  // in ppm of the full-scale output (K times the largest |input|).
  double nonlinearity_ppm = 0.0, sigma_nonlinearity_ppm = 0.0;
  double worst_input_rad_s = 0.0;
  std::vector<double> deviation_ppm;  // per step, same order as the input
  // Asymmetry: (K+ - K-) / K from output = bias + K input + (dK / 2) |input|.
  double asymmetry_ppm = 0.0, sigma_asymmetry_ppm = 0.0;
  double full_scale_rad_s = 0.0;
  double decades = 0.0;  // log10(largest / smallest |input|)
  bool ok = false;
  std::string error;  // what the series lacks (both signs, 1.5 decades, steps)
};
ScaleFactorSeries analyze_scale_factor(std::span<const RateStep> steps, double k_nominal = 1.0);

// Angle-dependent scale factor over whole turns of the pattern (antinode)
// angle, true and as read (atan2(S, R) / 4): the readout error
// e = readout - true angle fitted as offset + s theta + the 4 theta harmonic
// (a pickoff gain mismatch g gives a = -g/4 rad). The local scale factor is
// 1 + s + 4 A cos(4 theta + phase): it swings by +-4 A.
struct AngleDependentScaleFactor {
  HarmonicFit fit;             // on the true angle, error in rad
  double amplitude_deg = 0.0;  // A of the 4 theta readout error
  double sigma_amplitude_deg = 0.0;
  double scale_swing_ppm = 0.0;  // 4 A (rad/rad), ppm
  double sigma_scale_swing_ppm = 0.0;
  double mean_scale_error_ppm = 0.0;  // s over the turns
  bool ok = false;
  std::string error;
};
AngleDependentScaleFactor analyze_angle_readout(std::span<const double> true_angle_rad,
                                                std::span<const double> readout_angle_rad);

}  // namespace hrg::characterize
