// SPDX-License-Identifier: MIT
#include "firmware/estimator_port.hpp"

#include <cmath>

namespace hrg::fw {

void EstimatorPort::begin_window(double t_s) { (void)est_.begin_window(t_s); }

void EstimatorPort::add_sample(const ChainOutputs& s) {
  est::WaveSample w;
  w.t_s = s.t_s;
  w.a_A_v = s.a_a_v;
  w.a_B_v = s.a_b_v;
  w.theta_A_rad = s.theta_a_rad;
  w.E_v2 = s.e_v2;
  // Settling samples and sequencing errors are the accumulator's to count.
  (void)est_.add_sample(w);
}

void EstimatorPort::end_window() {
  if (est_.end_window() == est::Status::ok) {
    ++windows_ok_;
    dirty_ = true;
  } else {
    ++windows_bad_;
  }
}

void EstimatorPort::abort_window() {
  // est::Estimator has no abort: the samples fed before the abort (all taken
  // before the fault monitors fired) are folded in, and the window is counted
  // as aborted.
  if (!est_.window().window_open()) return;
  (void)est_.end_window();
  dirty_ = true;
  ++windows_bad_;
}

void EstimatorPort::solve() {
  if (!dirty_) return;
  dirty_ = false;
  const est::Solution s = est_.solve_and_accept();
  if (s.accepted()) ++solves_ok_;
  health_.solved = est_.has_model();
  health_.condition = s.cond.kappa_2;
  const auto& cov = est_.coverage_s();
  int covered = 0;
  for (double c : cov)
    covered += c > 0.0 ? 1 : 0;
  health_.coverage = static_cast<double>(covered) / static_cast<double>(cov.size());
}

Identification EstimatorPort::identification() const {
  Identification id;
  id.valid = est_.has_model();
  const est::Solution& s = est_.last_solution();
  for (int i = 0; i < est::kParams; ++i) {
    id.p[i] = id.valid ? est_.model()(i) : s.p(i);
    const double var = s.covariance(i, i);
    id.sigma[i] = var > 0.0 ? std::sqrt(var) : 0.0;
  }
  return id;
}

}  // namespace hrg::fw
