// SPDX-License-Identifier: MIT
#pragma once

#include <span>
#include <string>
#include <vector>

namespace hrg::characterize {

// One harmonic k theta of a fitted pattern: a sin k theta + b cos k theta.
struct Harmonic {
  int order = 0;
  double a_sin = 0.0, b_cos = 0.0;
  double sigma_a = 0.0, sigma_b = 0.0;  // 1 sigma, from the residuals
  double amplitude = 0.0;               // hypot(a, b)
  double sigma_amplitude = 0.0;         // first order, with the a-b covariance
  double phase_rad = 0.0;               // a sin + b cos = amplitude sin(k theta + phase)
};

// Least squares y(theta) = c0 [+ s theta] + sum_k (a_k sin k theta + b_k cos k theta):
// the angle-dependent bias over parked angles (orders {4}) or the readout error
// of a pattern turned through whole turns (orders {4}, or {2, 4, 8}, with the
// slope s taking a scale error).
struct HarmonicFit {
  double offset = 0.0, sigma_offset = 0.0;
  double slope = 0.0, sigma_slope = 0.0;  // per radian of theta; 0 unless asked for
  std::vector<Harmonic> harmonics;        // in the order asked
  double residual_rms = 0.0;
  std::size_t points = 0;
  bool ok = false;
  std::string error;  // why not ok: too few points, or the angles do not span the harmonics
};
HarmonicFit fit_harmonics(std::span<const double> theta_rad, std::span<const double> y,
                          std::span<const int> orders, bool with_slope = false);

}  // namespace hrg::characterize
