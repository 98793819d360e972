// SPDX-License-Identifier: MIT
#pragma once

namespace hrg::characterize {

// Regularized lower incomplete gamma function P(a, x), a > 0, x >= 0.
double gamma_p(double a, double x);

// Chi-square distribution with (possibly non-integer) dof degrees of freedom:
// cumulative probability and its inverse (the quantile), p in (0, 1).
double chi_square_cdf(double x, double dof);
double chi_square_quantile(double p, double dof);

}  // namespace hrg::characterize
