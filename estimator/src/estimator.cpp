// SPDX-License-Identifier: MIT
#include <estimator/estimator.hpp>

#include <numbers>

namespace hrg::est {

Status Estimator::end_window(bool fold) {
  const Status s = window_.end_window(scratch_);
  if (s == Status::ok) {
    check_window(scratch_);
    if (fold) ls_.add_window(scratch_);
  }
  // The loops re-acquire after the window: the D_Phi derivatives restart.
  control_.restart();
  pump_.restart();
  return s;
}

void Estimator::check_window(const WindowContribution& w) {
  const double var = last_.sigma_hat_v * last_.sigma_hat_v;
  const double dof = w.rows - w.intercepts;
  if (!has_model_ || !(var > 0.0) || !(dof > 0.0)) return;
  // RSS of this window alone at the accepted p: y'y - 2 p'H'y + p'H'H p.
  const ParamVector& p = model_;
  const ParamVector b = w.info.block<kParams, 1>(0, kParams);
  const ParamMatrix n = w.info.block<kParams, kParams>(0, 0);
  const double rss = w.info(kParams, kParams) - 2.0 * p.dot(b) + p.dot(n * p);
  last_misfit_ = rss / dof / var;
  ++windows_checked_;
}

Solution Estimator::solve_and_accept() {
  last_ = ls_.solve(config_.variant);
  if (last_.accepted()) {
    model_ = last_.p;
    has_model_ = true;
    control_.set_model(last_.p);
    pump_.set_model(last_.p);
  }
  return last_;
}

double Estimator::least_covered_theta_rad() const {
  // Bin i covers 4theta in [i, i+1) * 2pi/bins; its centre in theta is a quarter.
  const double four_theta =
      (ls_.least_covered_bin() + 0.5) * 2.0 * std::numbers::pi / kCoverageBins;
  return 0.25 * four_theta;
}

}  // namespace hrg::est
