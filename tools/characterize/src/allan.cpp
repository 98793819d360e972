// SPDX-License-Identifier: MIT
#include "characterize/allan.hpp"

#include <algorithm>
#include <cmath>

#include "characterize/chi_square.hpp"

namespace hrg::characterize {
namespace {

std::vector<std::size_t> default_factors(std::size_t n_angle, double tau0_s) {
  std::vector<std::size_t> m;
  for (std::size_t k = 1; n_angle >= 2 * k + 2; k *= 2)
    m.push_back(k);
  for (const double tau_s : {1.0, 3.0}) {
    const auto k = static_cast<std::size_t>(std::lround(tau_s / tau0_s));
    if (k >= 1 && n_angle >= 2 * k + 2) m.push_back(k);
  }
  std::sort(m.begin(), m.end());
  m.erase(std::unique(m.begin(), m.end()), m.end());
  return m;
}

double overlapping_avar(std::span<const double> x, std::size_t m, double tau_s) {
  const std::size_t terms = x.size() - 2 * m;
  double sum = 0.0;
  for (std::size_t i = 0; i < terms; ++i) {
    const double d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
    sum += d * d;
  }
  return sum / (2.0 * tau_s * tau_s * static_cast<double>(terms));
}

// Noise type from the log-log slope mu of sigma^2 around point i: white rate
// -1, flicker rate 0, random-walk rate +1; steeper than -1.5 is angle noise.
int alpha_from_slope(const std::vector<AllanPoint>& c, std::size_t i) {
  const std::size_t a = i == 0 ? 0 : i - 1;
  const std::size_t b = std::min(i + 1, c.size() - 1);
  if (a == b || !(c[a].adev > 0.0) || !(c[b].adev > 0.0)) return power_law::kWhiteRate;
  const double mu = 2.0 * std::log(c[b].adev / c[a].adev) / std::log(c[b].tau_s / c[a].tau_s);
  if (mu < -1.5) return power_law::kWhiteAngle;
  return std::clamp(static_cast<int>(std::lround(-mu - 1.0)), power_law::kRandomWalkRate,
                    power_law::kWhiteRate);
}

// Chi-square interval: edf s^2 / sigma^2 ~ chi2(edf), so the upper quantile
// gives the LOWER bound of sigma and the lower quantile the upper bound.
void add_confidence(std::vector<AllanPoint>& curve, std::size_t n_angle,
                    const AllanOptions& options) {
  const double p_tail = 0.5 * (1.0 - options.confidence);
  for (std::size_t i = 0; i < curve.size(); ++i) {
    AllanPoint& p = curve[i];
    p.alpha = options.alpha.value_or(alpha_from_slope(curve, i));
    p.edf = edf_overlapping_adev(p.alpha, p.m, n_angle);
    p.adev_lo = p.adev * std::sqrt(p.edf / chi_square_quantile(1.0 - p_tail, p.edf));
    p.adev_hi = p.adev * std::sqrt(p.edf / chi_square_quantile(p_tail, p.edf));
  }
}

}  // namespace

std::vector<AllanPoint> allan_from_angle(std::span<const double> angle, double tau0_s,
                                         const AllanOptions& options) {
  const std::size_t n = angle.size();
  const std::vector<std::size_t> factors =
      options.m.empty() ? default_factors(n, tau0_s) : options.m;
  std::vector<AllanPoint> curve;
  for (const std::size_t m : factors) {
    if (m == 0 || n < 2 * m + 2) continue;
    AllanPoint p;
    p.m = m;
    p.tau_s = static_cast<double>(m) * tau0_s;
    p.terms = n - 2 * m;
    p.adev = std::sqrt(overlapping_avar(angle, m, p.tau_s));
    curve.push_back(p);
  }
  add_confidence(curve, n, options);
  return curve;
}

std::vector<AllanPoint> allan_from_rate(std::span<const double> rate, double tau0_s,
                                        const AllanOptions& options) {
  std::vector<double> angle(rate.size() + 1, 0.0);
  for (std::size_t i = 0; i < rate.size(); ++i)
    angle[i + 1] = angle[i] + rate[i] * tau0_s;
  return allan_from_angle(angle, tau0_s, options);
}

}  // namespace hrg::characterize
