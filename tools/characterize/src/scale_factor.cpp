// SPDX-License-Identifier: MIT
#include "characterize/scale_factor.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace hrg::characterize {
namespace {

constexpr double kPpm = 1e6;

// Weighted least squares y = H p; the covariance scaled by the residuals when
// the weights are not absolute (no stated sigma).
struct LinearFit {
  Eigen::VectorXd p;
  Eigen::MatrixXd cov;
  Eigen::VectorXd residual;
  double sigma_unit = 1.0;  // a-posteriori sigma of a unit-weight step
};

LinearFit solve(const Eigen::MatrixXd& h, const Eigen::VectorXd& y, const Eigen::VectorXd& w,
                bool absolute_weights) {
  LinearFit f;
  const Eigen::MatrixXd hw = w.asDiagonal() * h;
  const Eigen::MatrixXd n = h.transpose() * hw;
  const Eigen::MatrixXd n_inv = n.inverse();
  f.p = n_inv * (hw.transpose() * y);
  f.residual = y - h * f.p;
  const double dof = static_cast<double>(h.rows() - h.cols());
  const double chi2 = f.residual.dot(w.asDiagonal() * f.residual);
  f.sigma_unit = absolute_weights ? 1.0 : std::sqrt(chi2 / dof);
  f.cov = n_inv * (f.sigma_unit * f.sigma_unit);
  return f;
}

std::string check_series(std::span<const RateStep> steps, double& decades) {
  std::size_t pos = 0, neg = 0;
  double lo = INFINITY, hi = 0.0;
  for (const RateStep& s : steps) {
    if (!std::isfinite(s.input_rad_s) || !std::isfinite(s.output_rad_s))
      return "scale factor: a step has a non-finite rate";
    if (s.input_rad_s > 0) ++pos;
    if (s.input_rad_s < 0) ++neg;
    const double a = std::fabs(s.input_rad_s);
    if (a > 0) lo = std::min(lo, a), hi = std::max(hi, a);
  }
  if (pos < 2 || neg < 2)
    return "scale factor: needs at least 2 steps of each sign (has " + std::to_string(pos) +
           " positive, " + std::to_string(neg) + " negative)";
  decades = std::log10(hi / lo);
  if (decades < 1.5)
    return "scale factor: the steps span " + std::to_string(decades) +
           " decades of input rate; IEEE 1431 asks for at least 1.5";
  return {};
}

}  // namespace

ScaleFactorSeries analyze_scale_factor(std::span<const RateStep> steps, double k_nominal) {
  ScaleFactorSeries r;
  r.error = check_series(steps, r.decades);
  if (!r.error.empty()) return r;
  const auto n = static_cast<Eigen::Index>(steps.size());
  const bool stated = std::all_of(steps.begin(), steps.end(),
                                  [](const RateStep& s) { return s.sigma_rad_s > 0.0; });
  Eigen::MatrixXd h(n, 3);
  Eigen::VectorXd y(n), w(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const RateStep& s = steps[static_cast<std::size_t>(i)];
    h.row(i) << 1.0, s.input_rad_s, 0.5 * std::fabs(s.input_rad_s);
    y(i) = s.output_rad_s;
    w(i) = stated ? 1.0 / (s.sigma_rad_s * s.sigma_rad_s) : 1.0;
    r.full_scale_rad_s = std::max(r.full_scale_rad_s, std::fabs(s.input_rad_s));
  }
  const LinearFit line = solve(h.leftCols(2), y, w, stated);
  r.bias_rad_s = line.p(0);
  r.sigma_bias_rad_s = std::sqrt(line.cov(0, 0));
  r.k = line.p(1);
  r.sigma_k = std::sqrt(line.cov(1, 1));
  r.k_error_ppm = (r.k / k_nominal - 1.0) * kPpm;
  r.sigma_k_error_ppm = r.sigma_k / k_nominal * kPpm;
  const double fs_out = std::fabs(r.k) * r.full_scale_rad_s;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double dev = line.residual(i) / fs_out * kPpm;
    r.deviation_ppm.push_back(dev);
    if (std::fabs(dev) >= std::fabs(r.nonlinearity_ppm)) {
      r.nonlinearity_ppm = std::fabs(dev);
      r.worst_input_rad_s = steps[static_cast<std::size_t>(i)].input_rad_s;
      // The worst step's own scatter (the fitted line's share is smaller).
      r.sigma_nonlinearity_ppm = line.sigma_unit / std::sqrt(w(i)) / fs_out * kPpm;
    }
  }
  const LinearFit asym = solve(h, y, w, stated);
  r.asymmetry_ppm = asym.p(2) / asym.p(1) * kPpm;
  r.sigma_asymmetry_ppm = std::sqrt(asym.cov(2, 2)) / std::fabs(asym.p(1)) * kPpm;
  r.ok = true;
  return r;
}

AngleDependentScaleFactor analyze_angle_readout(std::span<const double> true_angle_rad,
                                                std::span<const double> readout_angle_rad) {
  AngleDependentScaleFactor r;
  if (true_angle_rad.size() != readout_angle_rad.size()) {
    r.error = "angle readout: " + std::to_string(true_angle_rad.size()) + " true angles but " +
              std::to_string(readout_angle_rad.size()) + " readouts";
    return r;
  }
  std::vector<double> err;
  for (std::size_t i = 0; i < true_angle_rad.size(); ++i)
    err.push_back(readout_angle_rad[i] - true_angle_rad[i]);
  const int orders[] = {4};
  r.fit = fit_harmonics(true_angle_rad, err, orders, true);
  if (!r.fit.ok) {
    r.error = "angle readout: " + r.fit.error;
    return r;
  }
  const double deg = 180.0 / std::numbers::pi;
  const Harmonic& h4 = r.fit.harmonics.front();
  r.amplitude_deg = h4.amplitude * deg;
  r.sigma_amplitude_deg = h4.sigma_amplitude * deg;
  r.scale_swing_ppm = 4.0 * h4.amplitude * kPpm;
  r.sigma_scale_swing_ppm = 4.0 * h4.sigma_amplitude * kPpm;
  r.mean_scale_error_ppm = r.fit.slope * kPpm;
  r.ok = true;
  return r;
}

}  // namespace hrg::characterize
