// SPDX-License-Identifier: MIT
#include "estimator/damping_model_check.hpp"

#include <algorithm>
#include <cmath>

#include "estimator/augmented_least_squares.hpp"

namespace hrg::est {

namespace {
constexpr int kP = kModelCheckParams;
constexpr int kGamma = 3;
// Below this ratio of the smallest to the largest pivot of the
// Jacobi-scaled normal matrix the calibration's change is collinear with the
// reference damping (k constant): nothing to tell. (The pivots, not the
// eigenvalues: the check needs no eigen-solver of its own; 1e-10 for a
// condition number of ~1e10.)
constexpr double kMinPivotRatio = 1e-10;

bool collinear(const Eigen::Matrix<double, kP, kP>& n) {
  const Eigen::Matrix<double, kP, 1> d = n.diagonal();
  if (!(d.minCoeff() > 0.0) || !n.allFinite()) return true;
  const Eigen::Matrix<double, kP, 1> s = d.cwiseSqrt().cwiseInverse();
  const Eigen::Matrix<double, kP, kP> scaled = s.asDiagonal() * n * s.asDiagonal();
  const Eigen::Matrix<double, kP, 1> pivots = scaled.ldlt().vectorD();
  return !(pivots.minCoeff() > kMinPivotRatio * pivots.maxCoeff());
}
}  // namespace

void DampingModelCheck::begin_window() {
  open_ = true;
  sum_.setZero();
  sum2_.setZero();
  block_.setZero();
  in_block_ = 0;
  blocks_in_window_ = 0;
  samples_in_window_ = 0;
  int_r_ = int_s_ = int_k_ = 0.0;
}

Status DampingModelCheck::add_sample(const WaveSample& s) {
  if (!open_) return Status::not_in_window;
  if (!(std::isfinite(s.t_s) && std::isfinite(s.E_v2) && std::isfinite(s.theta_A_rad) &&
        std::isfinite(s.a_A_v) && std::isfinite(s.a_B_v) && std::isfinite(s.damping_scale)) ||
      !(s.E_v2 > 0.0)) {
    return Status::bad_sample;
  }
  if (samples_in_window_ > 0 && !(s.t_s > last_t_)) return Status::time_not_increasing;
  // r = R/E, s = S/E (dsp/wave_variables.hpp).
  const double p_over_e = s.p_over_e();
  const double r = p_over_e * std::cos(4.0 * s.theta_A_rad);
  const double sn = p_over_e * std::sin(4.0 * s.theta_A_rad);
  const double dk = s.damping_scale - 1.0;
  const double ln_e = std::log(s.E_v2);
  if (samples_in_window_ == 0) {
    t0_ = s.t_s;
    y0_ = ln_e;
  } else {
    // Trapezoidal integrals.
    const double h = 0.5 * (s.t_s - last_t_);
    int_r_ += h * (r + last_r_);
    int_s_ += h * (sn + last_s_);
    int_k_ += h * (dk + last_k_);
  }
  last_t_ = s.t_s;
  last_r_ = r;
  last_s_ = sn;
  last_k_ = dk;
  max_dk_ = std::max(max_dk_, std::fabs(dk));
  Vec v;
  v << -2.0 * (s.t_s - t0_), -2.0 * int_r_, -2.0 * int_s_, -2.0 * int_k_, ln_e - y0_;
  block_ += v;
  ++samples_in_window_;
  if (++in_block_ == kModelCheckBlockSamples) fold_block();
  return Status::ok;
}

void DampingModelCheck::fold_block() {
  const Vec v = block_ / static_cast<double>(kModelCheckBlockSamples);
  sum_ += v;
  sum2_.noalias() += v * v.transpose();
  ++blocks_in_window_;
  block_.setZero();
  in_block_ = 0;
}

Status DampingModelCheck::end_window() {
  if (!open_) return Status::not_in_window;
  open_ = false;
  if (blocks_in_window_ < 3) return Status::too_short;
  a_ += centred<kP + 1>(sum_, sum2_, static_cast<double>(blocks_in_window_));
  ++windows_;
  blocks_ += blocks_in_window_;
  return Status::ok;
}

DampingModelCheckResult DampingModelCheck::solve() const {
  DampingModelCheckResult r;
  r.windows = windows_;
  const int dof = blocks_ - windows_ - kP;
  if (max_dk_ == 0.0 || windows_ < kModelCheckMinWindows || dof <= 0) return r;
  if (collinear(a_.topLeftCorner<kP, kP>())) {
    r.status = Status::ill_conditioned;
    return r;
  }
  const AugmentedFit<kP> f = fit_augmented<kP, kP + 1>(a_, 0);
  const double nu = f.p(0);
  const double sigma_gamma = std::sqrt(f.n_inv(kGamma, kGamma) * f.rss / dof);
  if (!(nu > 0.0) || !std::isfinite(sigma_gamma) || !std::isfinite(f.p(kGamma))) {
    r.status = Status::ill_conditioned;
    return r;
  }
  r.status = Status::ok;
  r.nu_per_s = nu;
  r.factor = f.p(kGamma) / nu;
  r.factor_sigma = sigma_gamma / nu;
  r.refuted = (0.5 - r.factor) > kModelCheckSigmas * r.factor_sigma;
  r.supported = (r.factor - 0.5) > kModelCheckSigmas * r.factor_sigma;
  return r;
}

}  // namespace hrg::est
