// SPDX-License-Identifier: MIT
#include "characterize/noise_terms.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace hrg::characterize {
namespace {

// Log-log slope of the deviation around point i: least squares over the point
// and two neighbours each side (fewer at the ends), which steadies it against
// the scatter of the long-tau points.
double local_slope(std::span<const AllanPoint> c, std::size_t i) {
  const std::size_t a = i < 2 ? 0 : i - 2;
  const std::size_t b = std::min(i + 2, c.size() - 1);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t j = a; j <= b; ++j) {
    const double x = std::log(c[j].tau_s), y = std::log(c[j].adev);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double n = static_cast<double>(b - a + 1);
  const double den = n * sxx - sx * sx;
  return den > 0.0 ? (n * sxy - sx * sy) / den : std::numeric_limits<double>::quiet_NaN();
}

// The line of the given slope through each point, read at tau_read_s. It lies
// under every point's true value, so its level is at most the lowest upper
// bound; the points whose lower bound reaches that level rest on it.
struct LineFit {
  std::vector<bool> rests;  // per point
  std::size_t lowest = 0;   // the point with the lowest upper bound
};

double line_at(const AllanPoint& p, double v, double slope, double tau_read_s) {
  return v * std::pow(tau_read_s / p.tau_s, slope);
}

LineFit fit_line(std::span<const AllanPoint> curve, double slope, double tau_read_s) {
  LineFit f;
  double lowest_hi = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const double hi = line_at(curve[i], curve[i].adev_hi, slope, tau_read_s);
    if (hi < lowest_hi) lowest_hi = hi, f.lowest = i;
  }
  for (const AllanPoint& p : curve)
    f.rests.push_back(line_at(p, p.adev_lo, slope, tau_read_s) <= lowest_hi);
  return f;
}

SlopeReading reading_at(std::span<const AllanPoint> curve, std::size_t i, double slope,
                        double tau_read_s) {
  const AllanPoint& p = curve[i];
  SlopeReading r;
  r.value = line_at(p, p.adev, slope, tau_read_s);
  r.lo = line_at(p, p.adev_lo, slope, tau_read_s);
  r.hi = line_at(p, p.adev_hi, slope, tau_read_s);
  r.at_tau_s = p.tau_s;
  r.edf = p.edf;
  r.on_slope = std::fabs(local_slope(curve, i) - slope) <= 0.25;
  return r;
}

}  // namespace

SlopeReading read_on_slope(std::span<const AllanPoint> curve, double slope, double tau_read_s) {
  if (curve.empty()) return {};
  const LineFit f = fit_line(curve, slope, tau_read_s);
  std::size_t best = f.lowest;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const double distance = std::fabs(std::log(curve[i].tau_s / tau_read_s));
    if (f.rests[i] && distance < best_distance) best_distance = distance, best = i;
  }
  return reading_at(curve, best, slope, tau_read_s);
}

SlopeReading read_floor(std::span<const AllanPoint> curve) {
  if (curve.empty()) return {};
  return reading_at(curve, fit_line(curve, 0.0, 1.0).lowest, 0.0, 1.0);
}

NoiseTerms noise_terms(std::span<const AllanPoint> curve) {
  NoiseTerms t;
  t.arw = read_on_slope(curve, -0.5, 1.0);
  t.bias_instability = read_floor(curve);
  for (double* v : {&t.bias_instability.value, &t.bias_instability.lo, &t.bias_instability.hi})
    *v /= kFlickerFloorFactor;
  t.rate_random_walk = read_on_slope(curve, 0.5, 3.0);
  return t;
}

}  // namespace hrg::characterize
