// SPDX-License-Identifier: MIT
#include "sim_tools/analysis.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace hrg::simtools {

std::vector<AllanPoint> allan_deviation(std::span<const double> angle, double tau0_s) {
  std::vector<AllanPoint> out;
  const std::size_t n = angle.size();
  for (std::size_t m = 1; n >= 2 * m + 2; m *= 2) {
    double sum = 0.0;
    const std::size_t terms = n - 2 * m;
    for (std::size_t i = 0; i < terms; ++i) {
      const double d = angle[i + 2 * m] - 2.0 * angle[i + m] + angle[i];
      sum += d * d;
    }
    const double tau = static_cast<double>(m) * tau0_s;
    out.push_back({tau, std::sqrt(sum / (2.0 * tau * tau * static_cast<double>(terms))), terms});
  }
  return out;
}

double BiasFit::amplitude() const { return std::hypot(a_sin4, b_cos4); }

BiasFit fit_bias_4theta(std::span<const double> theta_rad, std::span<const double> bias) {
  BiasFit f;
  const std::size_t n = theta_rad.size();
  if (n < 4 || bias.size() != n) return f;
  Eigen::MatrixXd h(static_cast<Eigen::Index>(n), 3);
  Eigen::VectorXd y(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    h(r, 0) = 1.0;
    h(r, 1) = std::sin(4.0 * theta_rad[i]);
    h(r, 2) = std::cos(4.0 * theta_rad[i]);
    y(r) = bias[i];
  }
  const Eigen::Matrix3d hth = h.transpose() * h;
  Eigen::FullPivLU<Eigen::Matrix3d> lu(hth);
  if (lu.rank() < 3) return f;
  const Eigen::Vector3d p = lu.solve(h.transpose() * y);
  const Eigen::VectorXd res = y - h * p;
  const double dof = static_cast<double>(n) - 3.0;
  const double s2 = dof > 0 ? res.squaredNorm() / dof : 0.0;
  const Eigen::Matrix3d cov = lu.inverse() * s2;
  f.b0 = p(0);
  f.a_sin4 = p(1);
  f.b_cos4 = p(2);
  f.sigma_b0 = std::sqrt(cov(0, 0));
  f.sigma_a = std::sqrt(cov(1, 1));
  f.sigma_b = std::sqrt(cov(2, 2));
  f.residual_rms = std::sqrt(res.squaredNorm() / static_cast<double>(n));
  f.ok = true;
  return f;
}

double slope(std::span<const double> t, std::span<const double> y) {
  const std::size_t n = t.size();
  if (n < 2 || y.size() != n) return 0.0;
  double mt = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) {
    mt += t[i];
    my += y[i];
  }
  mt /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double stt = 0, sty = 0;
  for (std::size_t i = 0; i < n; ++i) {
    stt += (t[i] - mt) * (t[i] - mt);
    sty += (t[i] - mt) * (y[i] - my);
  }
  return stt > 0 ? sty / stt : 0.0;
}

}  // namespace hrg::simtools
