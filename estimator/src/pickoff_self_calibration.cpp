// SPDX-License-Identifier: MIT
#include "estimator/pickoff_self_calibration.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <numbers>

#include "estimator/conditioning.hpp"

namespace hrg::est {

void PickoffSelfCalibration::reset() { *this = PickoffSelfCalibration{}; }

Status PickoffSelfCalibration::begin_window() {
  if (open_) return Status::in_window;
  open_ = true;
  n_ = 0;
  sz_.setZero();
  szz_.setZero();
  szy_.setZero();
  sy_ = 0.0;
  syy_ = 0.0;
  int_c4_ = 0.0;
  int_s4_ = 0.0;
  turn_4th_ = 0.0;
  return Status::ok;
}

Status PickoffSelfCalibration::add_sample(const WaveSample& s) {
  if (!open_) return Status::not_in_window;
  if (!(std::isfinite(s.t_s) && std::isfinite(s.E_v2) && std::isfinite(s.theta_A_rad)) ||
      !(s.E_v2 > 0.0)) {
    return Status::bad_sample;
  }
  if (n_ > 0 && !(s.t_s > last_t_)) return Status::time_not_increasing;
  const double c4 = std::cos(4.0 * s.theta_A_rad);
  const double s4 = std::sin(4.0 * s.theta_A_rad);
  if (n_ == 0) {
    t0_ = s.t_s;
  } else {
    // Trapezoidal integrals of the anisotropy's 4theta pattern.
    const double h = s.t_s - last_t_;
    int_c4_ += 0.5 * h * (c4 + last_c4_);
    int_s4_ += 0.5 * h * (s4 + last_s4_);
    turn_4th_ += std::remainder(4.0 * s.theta_A_rad - last_4th_, 2.0 * std::numbers::pi);
  }
  last_4th_ = 4.0 * s.theta_A_rad;
  last_t_ = s.t_s;
  last_c4_ = c4;
  last_s4_ = s4;
  // ln E = -2 nu t - 2 dnu_C I_C - 2 dnu_S I_S - g cos4th + 2 b sin4th + c_w.
  Vec z;
  z << -2.0 * (s.t_s - t0_), -2.0 * int_c4_, -2.0 * int_s4_, -c4, 2.0 * s4;
  const double y = std::log(s.E_v2);
  sz_ += z;
  szz_.noalias() += z * z.transpose();
  szy_ += z * y;
  sy_ += y;
  syy_ += y * y;
  ++n_;
  return Status::ok;
}

Status PickoffSelfCalibration::end_window(int min_samples) {
  if (!open_) return Status::not_in_window;
  open_ = false;
  if (n_ < min_samples) return Status::too_short;
  // Centring within the window removes its offset c_w.
  const double n = static_cast<double>(n_);
  hh_.noalias() += szz_ - sz_ * sz_.transpose() / n;
  hy_.noalias() += szy_ - sz_ * (sy_ / n);
  yy_ += syy_ - sy_ * sy_ / n;
  ++windows_;
  if (std::fabs(turn_4th_) >= kSelfCalMinTurnRad) ++turning_;
  samples_ += n_;
  return Status::ok;
}

PickoffSelfCalResult PickoffSelfCalibration::solve(double max_kappa) const {
  PickoffSelfCalResult r;
  r.windows = windows_;
  r.samples = samples_;
  r.turning_windows = turning_;
  const int dof = samples_ - windows_ - kSelfCalParams;
  if (windows_ == 0 || dof <= 0) return r;
  r.kappa_2 = conditioning_of<kSelfCalParams>(hh_).kappa_2;
  if (turning_ == 0 || !(r.kappa_2 <= max_kappa)) {
    r.status = Status::ill_conditioned;
    return r;
  }
  const Eigen::LDLT<Mat> ldlt(hh_);
  const Vec p = ldlt.solve(hy_);
  const double rss = std::max(0.0, yy_ - p.dot(hy_));
  const double var = rss / dof;
  const Mat cov = ldlt.solve(Mat::Identity()) * var;
  r.status = Status::ok;
  r.nu_per_s = p(0);
  r.dnu_c_per_s = p(1);
  r.dnu_s_per_s = p(2);
  r.gain = p(3);
  r.misalignment_rad = p(4);
  r.gain_sigma = std::sqrt(cov(3, 3));
  r.misalignment_sigma_rad = std::sqrt(cov(4, 4));
  r.residual_rms = std::sqrt(var);
  return r;
}

}  // namespace hrg::est
