// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <numbers>
#include <span>

#include "characterize/allan.hpp"

namespace hrg::characterize {

// Flicker rate noise gives a flat Allan deviation sigma = sqrt(2 ln2 / pi) B =
// 0.664 B (IEEE 952 annex C, two-sided PSD B^2 / (2 pi f)); the bias
// instability B is the flat minimum divided by this factor.
inline const double kFlickerFloorFactor = std::sqrt(2.0 * std::numbers::ln2 / std::numbers::pi);

// A straight line of the given log-log slope under the Allan deviation curve,
// read at tau_read_s. Each noise term alone lies on such a line and the terms
// add in variance, so the line rests on the curve from below: its level is at
// most the lowest upper bound of the points, the points whose lower bound
// reaches that level rest on it, and it is read on the one nearest tau_read_s.
struct SlopeReading {
  double value = 0.0;  // the line at tau_read_s (rate units of the curve)
  double lo = 0.0;     // the same interval as the point it rests on
  double hi = 0.0;
  double at_tau_s = 0.0;  // tau of that point
  double edf = 0.0;
  // The curve's own slope around that point (fitted over +-2 points) is the
  // line's within 0.25; if not, the term is not resolved by the record and
  // value is only an upper bound.
  bool on_slope = false;
};
SlopeReading read_on_slope(std::span<const AllanPoint> curve, double slope, double tau_read_s);

// The flat line (slope 0), read on the point that bounds it lowest: the
// minimum where it is well determined, not a noisy last point of few terms.
SlopeReading read_floor(std::span<const AllanPoint> curve);

// IEEE 952 figures in SI units of the curve (rate in rad/s):
//   angle random walk N (rad/sqrt(s)):  sigma = N / sqrt(tau), read at tau = 1 s
//   bias instability B (rad/s):         flat minimum (read_floor) / 0.664
//   rate random walk K (rad/s/sqrt(s)): sigma = K sqrt(tau / 3), read at tau = 3 s
struct NoiseTerms {
  SlopeReading arw;
  SlopeReading bias_instability;
  SlopeReading rate_random_walk;
};
NoiseTerms noise_terms(std::span<const AllanPoint> curve);

// Units at the edges.
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr double arw_deg_per_sqrt_h(double rad_per_sqrt_s) {
  return rad_per_sqrt_s * kDegPerRad * 60.0;
}
constexpr double rate_deg_per_h(double rad_per_s) { return rad_per_s * kDegPerRad * 3600.0; }
constexpr double rrw_deg_per_h_per_sqrt_h(double rad_per_s_sqrt_s) {
  return rad_per_s_sqrt_s * kDegPerRad * 3600.0 * 60.0;
}

}  // namespace hrg::characterize
