// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace hrg::sim_run {

struct AllanPoint {
  double tau_s;
  double adev;  // same unit as the rate whose angle was given
  std::size_t terms;
};

// Overlapping Allan deviation of a rate from its integral (the angle), sampled
// every tau0_s: sigma^2(tau) = sum (x[i+2m] - 2 x[i+m] + x[i])^2 / (2 tau^2 (N - 2m)),
// at tau = m tau0 for m = 1, 2, 4, ... while N - 2m >= 2.
std::vector<AllanPoint> allan_deviation(std::span<const double> angle, double tau0_s);

// IEEE 1431 style angle-dependent bias: b(theta) = b0 + a sin 4theta + c cos 4theta,
// least squares over the parked angles.
struct BiasFit {
  double b0 = 0.0;
  double a_sin4 = 0.0;
  double b_cos4 = 0.0;
  double sigma_b0 = 0.0;  // 1-sigma from the residuals
  double sigma_a = 0.0;
  double sigma_b = 0.0;
  double residual_rms = 0.0;
  double amplitude() const;  // sqrt(a^2 + b^2): the angle-dependent part
  bool ok = false;           // needs at least 4 points that span 4 theta
};
BiasFit fit_bias_4theta(std::span<const double> theta_rad, std::span<const double> bias);

// Least-squares slope of y against t (e.g. angle error against time = bias).
double slope(std::span<const double> t, std::span<const double> y);

}  // namespace hrg::sim_run
