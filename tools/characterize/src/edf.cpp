// SPDX-License-Identifier: MIT
// Equivalent degrees of freedom of the overlapping Allan variance, after
// C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based
// on finite differences" (PTTI 2003): the variance estimate is a sum of
// correlated squared second differences; its edf follows from the
// autocovariance of those differences under a power-law spectrum. Exact sum
// over all lags (no large-M approximation): 3 m kernel evaluations per tau.
#include <algorithm>
#include <cmath>

#include "characterize/allan.hpp"

namespace hrg::characterize {
namespace {

// Generalized autocovariance kernel of the power-law noise (up to a factor).
double kernel_w(double t, int alpha) {
  const double a = std::fabs(t);
  switch (alpha) {
    case 2: return -a;
    case 1: return a == 0.0 ? 0.0 : t * t * std::log(a);
    case 0: return a * a * a;
    case -1: return a == 0.0 ? 0.0 : t * t * t * t * std::log(a);
    default: return a * a * a * a * a;  // -2
  }
}

// The kernel of the sampled angle. The angle samples here are exact integrals
// of the rate (point samples, F = infinity in Greenhall's notation), which for
// the rate noises is the kernel one order up: checked against Monte Carlo
// (white rate, m = 1: the exact moving-average edf; F = m is 17 % high there).
// Angle noises (alpha >= 1) have no such limit: they keep the filter of one
// sample, F = m.
double kernel_x(double t, double f, int alpha) {
  if (alpha <= 0) return kernel_w(t, alpha + 2);
  return f * f *
         (2.0 * kernel_w(t, alpha) - kernel_w(t - 1.0 / f, alpha) - kernel_w(t + 1.0 / f, alpha));
}

// Autocovariance of the second differences at lag t (in units of m samples).
double kernel_z(double t, double f, int alpha) {
  return 6.0 * kernel_x(t, f, alpha) - 4.0 * kernel_x(t - 1.0, f, alpha) -
         4.0 * kernel_x(t + 1.0, f, alpha) + kernel_x(t - 2.0, f, alpha) +
         kernel_x(t + 2.0, f, alpha);
}

}  // namespace

double edf_overlapping_adev(int alpha, std::size_t m, std::size_t n_angle) {
  alpha = std::clamp(alpha, -2, 2);
  if (m == 0 || n_angle < 2 * m + 2) return 0.0;
  const double f = static_cast<double>(m);  // filter factor of one sample
  const double s = static_cast<double>(m);  // stride 1 sample: fully overlapped
  const double terms = static_cast<double>(n_angle - 2 * m);
  const double lags = std::min(terms, 3.0 * s);  // beyond 3 m the differences are independent
  const double z0 = kernel_z(0.0, f, alpha);
  double sum = z0 * z0;
  const double zj = kernel_z(lags / s, f, alpha);
  sum += (1.0 - lags / terms) * zj * zj;
  for (std::size_t j = 1; static_cast<double>(j) < lags; ++j) {
    const double jd = static_cast<double>(j);
    const double z = kernel_z(jd / s, f, alpha);
    sum += 2.0 * (1.0 - jd / terms) * z * z;
  }
  return terms * z0 * z0 / sum;
}

}  // namespace hrg::characterize
