// SPDX-License-Identifier: MIT
#pragma once

// Incremental least squares over all free-decay windows (paper sections 3-5).
//
// The state is the 6x6 augmented matrix [N b; b' yy] summed over windows
// (WindowAccumulator builds one per window). Every variant of the paper is a
// solve on the same state:
//   joint         N p = b over all five parameters (eqs. 20-21)
//   damping_only  the (nu, dnu_C, dnu_S) block, split taken as zero (eqs. 10-11)
//   split_only    the (nu, dw_C, dw_S) block, anisotropy taken as zero (eqs. 15-16)
//   alternating   block Gauss-Seidel between eqs. 18 and 19; converges to joint
// A variant that leaves a present effect out is biased by the omitted-variable
// term N_ss^-1 N_so p_o (the effect's regressors projected on the kept ones).
//
// Forgetting: with forgetting_time_s = tau > 0, the state is multiplied by
// exp(-(t_end - t_last)/tau) before a window is added, so the model follows
// temperature and ageing with memory tau. tau = 0 keeps all windows.
//
// Covariance: sigma_hat^2 N^-1 with sigma_hat^2 = RSS / (rows - intercepts - k),
// sigma_hat being the per-sample amplitude noise (the rows are scaled so).
// Cramer-Rao bound: sigma^2 N^-1 for a given per-sample noise sigma.
//
// Context: task level; add_window costs one 6x6 scale-add, solve one 5x5
// eigen-decomposition and LDL^T. No heap, no exceptions.

#include <estimator/conditioning.hpp>
#include <estimator/types.hpp>
#include <estimator/window_accumulator.hpp>

namespace hrg::est {

struct Solution {
  Status status{Status::no_data};
  Variant variant{Variant::joint};
  ParamVector p = ParamVector::Zero();           // unsolved entries are 0
  ParamMatrix covariance = ParamMatrix::Zero();  // sigma_hat^2 N^-1 on the solved block
  double sigma_hat_v{0};                         // residual per-sample amplitude noise
  Conditioning cond{};
  int iterations{0};  // alternating scheme only
  bool accepted() const { return status == Status::ok; }
};

class NormalEquations {
 public:
  struct Config {
    double forgetting_time_s = 0.0;  // 0: no forgetting
    double max_kappa_2 = 1.0e3;      // refuse estimates beyond this
    int min_windows = 3;
    int alternating_max_iterations = 200;
    double alternating_tolerance = 1e-12;  // relative step size
  };

  NormalEquations() = default;
  explicit NormalEquations(const Config& config) : config_(config) {}

  void add_window(const WindowContribution& w);
  void reset();
  // New memory from the next window on (0: none); what is held is kept.
  void set_forgetting_time_s(double tau_s) { config_.forgetting_time_s = tau_s; }
  Solution solve(Variant v) const;

  // Cramer-Rao bound on the five parameters for the windows taken, given the
  // per-sample (control-rate) white noise std of a_A and a_B. Zero matrix if N
  // is singular.
  ParamMatrix cramer_rao_bound(double sigma_v) const;

  const AugmentedMatrix& state() const { return m_; }
  double windows() const { return windows_; }
  double rows() const { return rows_; }
  const CoverageHistogram& coverage_s() const { return coverage_s_; }
  // Smallest coverage over the bins, seconds; the scheduler fills that bin next.
  int least_covered_bin() const;
  // Conditioning of the joint normal matrix now.
  Conditioning conditioning() const;
  const Config& config() const { return config_; }

 private:
  Config config_{};
  AugmentedMatrix m_ = AugmentedMatrix::Zero();
  double rows_{0};
  double intercepts_{0};
  double windows_{0};
  double t_last_s_{0};
  bool have_window_{false};
  CoverageHistogram coverage_s_{};
};

}  // namespace hrg::est
