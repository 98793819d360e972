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
//
// Parks that sit at nearly one 4 theta (a long run on a still table, whose
// pattern drifts to its equilibrium angle) leave the offset and the 4 theta
// terms inseparable: the fit can return a large b0 and a large ADB that
// cancel at the parks' angle. The fit is then `degenerate()`: the condition
// of its Jacobi-scaled normal matrix [1, sin 4th, cos 4th] (1 for parks
// spread evenly over a 4 theta turn; the worst combination's noise grows as
// its square root) is above kMaxBiasFitCondition, and the plain mean of the
// parks' biases is the figure to report, not the ADB.
inline constexpr double kMaxBiasFitCondition = 100.0;  // 10x noise on the worst combination
struct BiasFit {
  double b0 = 0.0;
  double a_sin4 = 0.0;
  double b_cos4 = 0.0;
  double sigma_b0 = 0.0;  // 1-sigma from the residuals
  double sigma_a = 0.0;
  double sigma_b = 0.0;
  double residual_rms = 0.0;
  // The parks' geometry and plain mean, set whenever there are points (also
  // when the fit itself is refused).
  double condition = 0.0;        // 2-norm condition, Jacobi-scaled (infinite: rank deficient)
  double span_rad = 0.0;         // pattern angle spanned: smallest 4 theta arc holding all, / 4
  double park_mean = 0.0;        // plain mean of the biases
  double sigma_park_mean = 0.0;  // their scatter / sqrt(n)
  std::size_t points = 0;
  double amplitude() const;  // sqrt(a^2 + b^2): the angle-dependent part
  // Enough parks (more than the 3 unknowns) at too narrow a spread of angles.
  bool degenerate() const { return points > 3 && !(condition <= kMaxBiasFitCondition); }
  bool ok = false;  // needs at least 4 points that span 4 theta
};
BiasFit fit_bias_4theta(std::span<const double> theta_rad, std::span<const double> bias);

// Least-squares slope of y against t (e.g. angle error against time = bias).
double slope(std::span<const double> t, std::span<const double> y);

}  // namespace hrg::sim_run
