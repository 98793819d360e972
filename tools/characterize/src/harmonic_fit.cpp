// SPDX-License-Identifier: MIT
#include "characterize/harmonic_fit.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace hrg::characterize {
namespace {

Harmonic harmonic_from(int order, Eigen::Index i, const Eigen::VectorXd& p,
                       const Eigen::MatrixXd& cov) {
  Harmonic h;
  h.order = order;
  h.a_sin = p(i);
  h.b_cos = p(i + 1);
  h.sigma_a = std::sqrt(cov(i, i));
  h.sigma_b = std::sqrt(cov(i + 1, i + 1));
  h.amplitude = std::hypot(h.a_sin, h.b_cos);
  h.phase_rad = std::atan2(h.b_cos, h.a_sin);
  if (h.amplitude > 0.0) {
    const double var = (h.a_sin * h.a_sin * cov(i, i) + h.b_cos * h.b_cos * cov(i + 1, i + 1) +
                        2.0 * h.a_sin * h.b_cos * cov(i, i + 1)) /
                       (h.amplitude * h.amplitude);
    h.sigma_amplitude = std::sqrt(std::max(var, 0.0));
  } else {
    h.sigma_amplitude = std::sqrt(0.5 * (cov(i, i) + cov(i + 1, i + 1)));
  }
  return h;
}

}  // namespace

HarmonicFit fit_harmonics(std::span<const double> theta_rad, std::span<const double> y,
                          std::span<const int> orders, bool with_slope) {
  HarmonicFit f;
  const auto n = static_cast<Eigen::Index>(theta_rad.size());
  const Eigen::Index cols = 1 + (with_slope ? 1 : 0) + 2 * static_cast<Eigen::Index>(orders.size());
  f.points = theta_rad.size();
  if (y.size() != theta_rad.size()) {
    f.error = "harmonic fit: " + std::to_string(theta_rad.size()) + " angles but " +
              std::to_string(y.size()) + " values";
    return f;
  }
  if (n <= cols) {
    f.error = "harmonic fit: " + std::to_string(n) + " points for " + std::to_string(cols) +
              " unknowns (needs more points than unknowns)";
    return f;
  }
  Eigen::MatrixXd h(n, cols);
  Eigen::VectorXd v(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    const double th = theta_rad[static_cast<std::size_t>(r)];
    Eigen::Index c = 0;
    h(r, c++) = 1.0;
    if (with_slope) h(r, c++) = th;
    for (const int k : orders) {
      h(r, c++) = std::sin(k * th);
      h(r, c++) = std::cos(k * th);
    }
    v(r) = y[static_cast<std::size_t>(r)];
  }
  const Eigen::MatrixXd hth = h.transpose() * h;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(hth);
  if (lu.rank() < cols) {
    f.error = "harmonic fit: the angles do not span the harmonics asked for";
    return f;
  }
  const Eigen::VectorXd p = lu.solve(h.transpose() * v);
  const Eigen::VectorXd res = v - h * p;
  const double s2 = res.squaredNorm() / static_cast<double>(n - cols);
  const Eigen::MatrixXd cov = lu.inverse() * s2;
  Eigen::Index c = 0;
  f.offset = p(c);
  f.sigma_offset = std::sqrt(cov(c, c));
  ++c;
  if (with_slope) {
    f.slope = p(c);
    f.sigma_slope = std::sqrt(cov(c, c));
    ++c;
  }
  for (const int k : orders) {
    f.harmonics.push_back(harmonic_from(k, c, p, cov));
    c += 2;
  }
  f.residual_rms = std::sqrt(res.squaredNorm() / static_cast<double>(n));
  f.ok = true;
  return f;
}

}  // namespace hrg::characterize
