// SPDX-License-Identifier: MIT
#include "characterize/chi_square.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hrg::characterize {
namespace {

constexpr double kEps = 1e-15;

// Power series of P(a, x); converges fast for x < a + 1.
double gamma_p_series(double a, double x, double log_prefactor) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < 100000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * kEps) break;
  }
  return sum * std::exp(log_prefactor);
}

// Continued fraction of Q(a, x) = 1 - P(a, x) (modified Lentz); for x >= a + 1.
double gamma_q_fraction(double a, double x, double log_prefactor) {
  const double tiny = std::numeric_limits<double>::min() / kEps;
  double b = x + 1.0 - a;
  double c = 1.0 / tiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEps) break;
  }
  return std::exp(log_prefactor) * h;
}

}  // namespace

double gamma_p(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0) return 0.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) return gamma_p_series(a, x, log_prefactor);
  return 1.0 - gamma_q_fraction(a, x, log_prefactor);
}

double chi_square_cdf(double x, double dof) { return x <= 0.0 ? 0.0 : gamma_p(0.5 * dof, 0.5 * x); }

double chi_square_quantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  // Bracket then bisect on the log of x: the cdf is monotone, and bisection
  // in log x keeps the relative precision for the tiny quantiles of small dof.
  double lo = 1e-300, hi = std::max(1.0, dof);
  while (chi_square_cdf(hi, dof) < p)
    hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = std::sqrt(lo * hi);
    (chi_square_cdf(mid, dof) < p ? lo : hi) = mid;
    if (hi - lo <= hi * 1e-14) break;
  }
  return 0.5 * (lo + hi);
}

}  // namespace hrg::characterize
