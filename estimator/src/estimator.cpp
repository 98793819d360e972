// SPDX-License-Identifier: MIT
#include <estimator/estimator.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace hrg::est {

Status Estimator::end_window(bool fold) {
  const Status s = window_.end_window(scratch_);
  if (s == Status::ok) {
    check_window(scratch_);
    if (fold) {
      ls_.add_window(scratch_);
      if (t_first_window_s_ < 0.0) t_first_window_s_ = scratch_.t_end_s;
      t_last_window_s_ = scratch_.t_end_s;
    }
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

void Estimator::check_known_gap() {
  if (!config_.gap.known() || gap_refuted_ || pump_.fit_s() == gap_checked_fit_s_) return;
  gap_checked_fit_s_ = pump_.fit_s();
  if (!pump_.valid()) return;
  // In the fit's units, (b1, b2) = b0 (eps_p, eps_q) / 2.
  const double half_b0 = 0.5 * pump_.coefficients()(0);
  const Config::KnownGap& k = config_.gap;
  const Eigen::Vector2d g0(half_b0 * k.eps_p, half_b0 * k.eps_q);
  const Eigen::Vector2d s0(half_b0 * k.sigma_eps_p, half_b0 * k.sigma_eps_q);
  const Eigen::Matrix2d c0 = s0.cwiseProduct(s0).asDiagonal();
  const double min_sigmas = config_.pump.min_gap_sigmas;
  if (min_sigmas > 0.0 && pump_.gap_sigmas_from(g0, c0) >= min_sigmas) gap_refuted_ = true;
}

Solution Estimator::solve_and_accept() {
  last_ = ls_.solve(config_.variant);
  if (last_.accepted()) {
    update_forgetting(last_);
    model_ = last_.p;
    has_model_ = true;
    control_.set_model(last_.p);
    pump_.set_model(last_.p, last_.covariance);
  }
  return last_;
}

void Estimator::update_forgetting(const Solution& s) {
  const Forgetting& f = config_.forgetting;
  if (!f.adaptive || config_.ls.forgetting_time_s > 0.0) return;
  const double t = t_last_window_s_;
  if (!have_anchor_) {
    if (ls_.windows() < f.min_windows) return;
    anchor_ = s;
    t_anchor_s_ = t;
    have_anchor_ = true;
    return;
  }
  const double span_s = t - t_anchor_s_;
  if (!(span_s > 0.0)) return;
  const double tau_now = ls_.config().forgetting_time_s;
  const double data_span_s = tau_now > 0.0 ? tau_now : t - t_first_window_s_;
  double tau = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kParams; ++i) {
    const double c_now = s.covariance(i, i);
    const double c_anchor = anchor_.covariance(i, i);
    if (!(c_now > 0.0) || !(c_anchor > 0.0)) continue;
    // Nested fits (no forgetting): the difference has variance C_a - C_now;
    // with forgetting the two are closer to independent.
    const double var = std::max(tau_now > 0.0 ? c_anchor + c_now : c_anchor - c_now, 0.01 * c_now);
    const double moved = std::fabs(s.p(i) - anchor_.p(i));
    if (moved <= f.move_sigmas * std::sqrt(var)) continue;
    const double rate = moved / span_s;
    tau = std::min(tau, std::cbrt(c_now * data_span_s / (2.0 * rate * rate)));
  }
  if (std::isfinite(tau)) {
    ls_.set_forgetting_time_s(std::max(tau, f.min_s));
    anchor_ = s;
    t_anchor_s_ = t;
  } else if (tau_now > 0.0 && span_s > tau_now) {
    ls_.set_forgetting_time_s(span_s);
  } else if (tau_now == 0.0 &&
             anchor_.covariance(kDnuC, kDnuC) > 4.0 * s.covariance(kDnuC, kDnuC)) {
    // The anchor holds under a quarter of the information now: a newer one
    // (the test compares the new data with the old, both of weight).
    anchor_ = s;
    t_anchor_s_ = t;
  }
}

double Estimator::least_covered_theta_rad() const {
  // Bin i covers 4theta in [i, i+1) * 2pi/bins; its centre in theta is a quarter.
  const double four_theta =
      (ls_.least_covered_bin() + 0.5) * 2.0 * std::numbers::pi / kCoverageBins;
  return 0.25 * four_theta;
}

}  // namespace hrg::est
