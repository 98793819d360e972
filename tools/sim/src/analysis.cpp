// SPDX-License-Identifier: MIT
#include "sim_run/analysis.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "characterize/allan.hpp"
#include "characterize/harmonic_fit.hpp"

namespace hrg::sim_run {

std::vector<AllanPoint> allan_deviation(std::span<const double> angle, double tau0_s) {
  characterize::AllanOptions octaves;
  for (std::size_t m = 1; angle.size() >= 2 * m + 2; m *= 2)
    octaves.m.push_back(m);
  std::vector<AllanPoint> out;
  for (const auto& p : characterize::allan_from_angle(angle, tau0_s, octaves))
    out.push_back({p.tau_s, p.adev, p.terms});
  return out;
}

double BiasFit::amplitude() const { return std::hypot(a_sin4, b_cos4); }

namespace {

// Condition of the fit's normal matrix for [1, sin 4th, cos 4th], scaled to
// a unit diagonal (as the estimator measures its own).
double fit_condition(std::span<const double> theta_rad) {
  Eigen::Matrix3d n = Eigen::Matrix3d::Zero();
  for (const double th : theta_rad) {
    const Eigen::Vector3d h(1.0, std::sin(4.0 * th), std::cos(4.0 * th));
    n += h * h.transpose();
  }
  const Eigen::Vector3d d = n.diagonal().cwiseSqrt();
  if (!(d.minCoeff() > 0.0)) return std::numeric_limits<double>::infinity();
  const Eigen::Matrix3d s = d.cwiseInverse().asDiagonal() * n * d.cwiseInverse().asDiagonal();
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(s).eigenvalues();
  return ev(0) > 0.0 ? ev(2) / ev(0) : std::numeric_limits<double>::infinity();
}

// Pattern angle spanned by the parks: the 4 theta circle less its largest
// empty gap, over 4.
double span_4theta_rad(std::span<const double> theta_rad) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  std::vector<double> a;
  a.reserve(theta_rad.size());
  for (const double th : theta_rad) {
    const double w = std::fmod(4.0 * th, kTwoPi);
    a.push_back(w < 0.0 ? w + kTwoPi : w);
  }
  if (a.size() < 2) return 0.0;
  std::sort(a.begin(), a.end());
  double gap = a.front() + kTwoPi - a.back();
  for (std::size_t i = 1; i < a.size(); ++i)
    gap = std::max(gap, a[i] - a[i - 1]);
  return (kTwoPi - gap) / 4.0;
}

void set_geometry(BiasFit& f, std::span<const double> theta_rad, std::span<const double> bias) {
  f.points = bias.size();
  if (f.points == 0 || theta_rad.size() != bias.size()) return;
  double sum = 0.0, sum2 = 0.0;
  for (const double b : bias)
    sum += b;
  f.park_mean = sum / static_cast<double>(f.points);
  for (const double b : bias)
    sum2 += (b - f.park_mean) * (b - f.park_mean);
  if (f.points > 1) {
    const double n = static_cast<double>(f.points);
    f.sigma_park_mean = std::sqrt(sum2 / (n - 1.0) / n);
  }
  f.condition = fit_condition(theta_rad);
  f.span_rad = span_4theta_rad(theta_rad);
}

}  // namespace

BiasFit fit_bias_4theta(std::span<const double> theta_rad, std::span<const double> bias) {
  BiasFit f;
  set_geometry(f, theta_rad, bias);
  const int orders[] = {4};
  const characterize::HarmonicFit h = characterize::fit_harmonics(theta_rad, bias, orders);
  if (!h.ok) return f;
  f.b0 = h.offset;
  f.sigma_b0 = h.sigma_offset;
  f.a_sin4 = h.harmonics[0].a_sin;
  f.b_cos4 = h.harmonics[0].b_cos;
  f.sigma_a = h.harmonics[0].sigma_a;
  f.sigma_b = h.harmonics[0].sigma_b;
  f.residual_rms = h.residual_rms;
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

}  // namespace hrg::sim_run
