// SPDX-License-Identifier: MIT
#include "fit.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace hrg::audit::detail {

namespace {

double sum_sq(const std::vector<double>& r) {
  double s = 0.0;
  for (double v : r)
    s += v * v;
  return s;
}

}  // namespace

FitResult fit(const Dataset& d, const Params& start, const Mask& free, const EvalOptions& o,
              int max_iterations) {
  std::vector<int> idx;
  for (int i = 0; i < kParamCount; ++i) {
    if (free[static_cast<std::size_t>(i)]) idx.push_back(i);
  }
  const auto m = static_cast<Eigen::Index>(idx.size());
  FitResult out;
  out.p = start;
  std::vector<double> r0, r1;
  evaluate(d, out.p, o, r0);
  double chi2 = sum_sq(r0);
  double lambda = 1e-3;
  Eigen::MatrixXd jtj(m, m);
  Eigen::VectorXd jtr(m);
  for (int it = 0; it < max_iterations; ++it) {
    out.iterations = it + 1;
    // Jacobian in scaled parameters, accumulated column by column.
    const auto nr = static_cast<Eigen::Index>(r0.size());
    Eigen::MatrixXd jac(nr, m);
    for (Eigen::Index c = 0; c < m; ++c) {
      const auto pi = static_cast<std::size_t>(idx[static_cast<std::size_t>(c)]);
      Params q = out.p;
      const double h = 1e-3 * param_scale(static_cast<int>(pi));
      q[pi] += h;
      evaluate(d, q, o, r1);
      for (Eigen::Index k = 0; k < nr; ++k) {
        jac(k, c) = (r1[static_cast<std::size_t>(k)] - r0[static_cast<std::size_t>(k)]) / 1e-3;
      }
    }
    const Eigen::Map<const Eigen::VectorXd> rv(r0.data(), nr);
    jtj = jac.transpose() * jac;
    jtr = jac.transpose() * rv;
    bool improved = false;
    for (int tries = 0; tries < 12 && !improved; ++tries) {
      Eigen::MatrixXd a = jtj;
      for (Eigen::Index k = 0; k < m; ++k)
        a(k, k) += lambda * std::max(jtj(k, k), 1e-12);
      const Eigen::VectorXd step = a.ldlt().solve(-jtr);
      Params q = out.p;
      for (Eigen::Index c = 0; c < m; ++c) {
        const auto pi = static_cast<std::size_t>(idx[static_cast<std::size_t>(c)]);
        q[pi] += step(c) * param_scale(static_cast<int>(pi));
      }
      evaluate(d, q, o, r1);
      const double c1 = sum_sq(r1);
      if (std::isfinite(c1) && c1 <= chi2) {
        const double gain = chi2 - c1;
        out.p = q;
        r0.swap(r1);
        chi2 = c1;
        lambda = std::max(lambda / 5.0, 1e-9);
        improved = true;
        if (gain < 1e-6 * std::max(1.0, chi2) || gain < 1e-3) out.converged = true;
      } else {
        lambda *= 8.0;
      }
    }
    if (!improved || out.converged) {
      out.converged = true;
      break;
    }
  }
  out.chi2 = chi2;
  out.n_res = r0.size();
  // Covariance in noise units: (J^T J)^-1 of the scaled parameters.
  if (m > 0) {
    const Eigen::MatrixXd cov = jtj.ldlt().solve(Eigen::MatrixXd::Identity(m, m));
    for (Eigen::Index c = 0; c < m; ++c) {
      const auto pi = static_cast<std::size_t>(idx[static_cast<std::size_t>(c)]);
      out.sigma[pi] = std::sqrt(std::max(cov(c, c), 0.0)) * param_scale(static_cast<int>(pi));
    }
  }
  return out;
}

}  // namespace hrg::audit::detail
