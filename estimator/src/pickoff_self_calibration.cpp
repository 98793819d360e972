// SPDX-License-Identifier: MIT
#include "estimator/pickoff_self_calibration.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "estimator/augmented_least_squares.hpp"
#include "estimator/conditioning.hpp"

namespace hrg::est {

namespace {

constexpr int kE = kSelfCalParams;
constexpr int kQ = kSelfCalQuadParams;
// Columns of the level-of-E row.
constexpr int kRho = 3;
constexpr int kBh = 4;
constexpr int kHc = 5;
constexpr int kHs = 6;
// Column of the quadrature row.
constexpr int kPhi = 2;

// Subtracts sum_j d_j z_j from the observation of an augmented state
// (y' = y - d.z), exact on the accumulated sums: A' = T A T'.
template <int A>
void subtract_from_observation(Eigen::Matrix<double, A, A>& aug,
                               const Eigen::Matrix<double, A, 1>& d) {
  Eigen::Matrix<double, A, A> t = Eigen::Matrix<double, A, A>::Identity();
  t.row(A - 1) -= d.transpose();
  aug = t * aug * t.transpose();
}

// rho (the 4theta coefficient of ln E) of a gain mismatch and back.
double rho_of_gain(double g) {
  const double k = (1.0 + g) * (1.0 + g);
  return (k - 1.0) / (k + 1.0);
}

// The pickoff gain and misalignment of a fit's level-pattern coefficients
// (rho, bh) and their variances; `held` false outside the map the model
// holds for.
struct LevelPattern {
  bool held = false;
  double gain = 0.0;
  double gain_sigma = 0.0;
  double misalignment_rad = 0.0;
  double misalignment_sigma_rad = 0.0;
};

LevelPattern level_pattern(double rho, double bh, double var_rho, double var_bh) {
  LevelPattern l;
  const double sin2b = 2.0 * bh * std::sqrt(std::max(0.0, 1.0 - rho * rho));
  if (!(std::fabs(rho) < 0.5) || !(std::fabs(sin2b) < 0.5)) return l;
  l.held = true;
  // rho = (k - 1)/(k + 1) with k = (1 + g)^2: 1 + g = sqrt((1 + rho)/(1 - rho)).
  l.gain = std::sqrt((1.0 + rho) / (1.0 - rho)) - 1.0;
  l.gain_sigma = std::sqrt(var_rho) / ((1.0 - rho) * std::sqrt(1.0 - rho * rho));
  l.misalignment_rad = 0.5 * std::asin(sin2b);
  l.misalignment_sigma_rad =
      std::sqrt(var_bh) * std::sqrt(1.0 - rho * rho) / std::cos(2.0 * l.misalignment_rad);
  return l;
}

}  // namespace

void PickoffSelfCalibration::reset() { *this = PickoffSelfCalibration{}; }

Status PickoffSelfCalibration::begin_window() {
  if (open_) return Status::in_window;
  open_ = true;
  n_ = 0;
  samples_in_window_ = 0;
  in_block_ = 0;
  block_e_.setZero();
  block_q_.setZero();
  se_.setZero();
  see_.setZero();
  sq_.setZero();
  sqq_.setZero();
  int_r_ = int_s_ = int_c4_ = int_s4_ = 0.0;
  turn_4th_ = 0.0;
  return Status::ok;
}

Status PickoffSelfCalibration::add_sample(const WaveSample& s) {
  if (!open_) return Status::not_in_window;
  if (!(std::isfinite(s.t_s) && std::isfinite(s.E_v2) && std::isfinite(s.theta_A_rad) &&
        std::isfinite(s.a_A_v) && std::isfinite(s.a_B_v)) ||
      !(s.E_v2 > 0.0)) {
    return Status::bad_sample;
  }
  if (samples_in_window_ > 0 && !(s.t_s > last_t_)) return Status::time_not_increasing;
  const double c4 = std::cos(4.0 * s.theta_A_rad);
  const double s4 = std::sin(4.0 * s.theta_A_rad);
  // r = R/E, s = S/E (dsp/wave_variables.hpp), the quadrature reading Q/E.
  const double p_over_e = s.p_over_e();
  const double r = p_over_e * c4;
  const double sn = p_over_e * s4;
  const double qn = 2.0 * s.a_A_v * s.a_B_v / s.E_v2;
  const double ln_e = std::log(s.E_v2);
  if (samples_in_window_ == 0) {
    t0_ = s.t_s;
    y0_ = ln_e;
  } else {
    // Trapezoidal integrals of the anisotropy's and the split's patterns.
    const double h = 0.5 * (s.t_s - last_t_);
    int_r_ += h * (r + last_r_);
    int_s_ += h * (sn + last_s_);
    int_c4_ += h * (c4 + last_c4_);
    int_s4_ += h * (s4 + last_s4_);
    turn_4th_ += std::remainder(4.0 * s.theta_A_rad - last_4th_, 2.0 * std::numbers::pi);
  }
  last_4th_ = 4.0 * s.theta_A_rad;
  last_t_ = s.t_s;
  last_r_ = r;
  last_s_ = sn;
  last_c4_ = c4;
  last_s4_ = s4;
  VecE v;
  v << -2.0 * (s.t_s - t0_), -2.0 * int_r_, -2.0 * int_s_, -r, 2.0 * sn, 0.5 * (r * r - sn * sn),
      r * sn, ln_e - y0_;
  VecQ q;
  q << 2.0 * int_s4_, -2.0 * int_c4_, s4, qn;
  block_e_ += v;
  block_q_ += q;
  ++samples_in_window_;
  if (++in_block_ == kSelfCalBlockSamples) fold_block();
  return Status::ok;
}

void PickoffSelfCalibration::fold_block() {
  // The block's means are one row each: the model is linear in the columns.
  const double inv = 1.0 / static_cast<double>(kSelfCalBlockSamples);
  const VecE v = block_e_ * inv;
  const VecQ q = block_q_ * inv;
  se_ += v;
  see_.noalias() += v * v.transpose();
  sq_ += q;
  sqq_.noalias() += q * q.transpose();
  ++n_;
  block_e_.setZero();
  block_q_.setZero();
  in_block_ = 0;
}

Status PickoffSelfCalibration::end_window(int min_samples) {
  if (!open_) return Status::not_in_window;
  open_ = false;
  // A partial last block is left out.
  if (samples_in_window_ < min_samples || n_ < 3) return Status::too_short;
  const double n = static_cast<double>(n_);
  // Centring removes the window's offset.
  ae_ += centred<kE + 1>(se_, see_, n);
  aq_ += centred<kQ + 1>(sq_, sqq_, n);
  // Detrending (offset and slope of its own: the per-window decay test)
  // projects every column on [1, t] of this window: A - C' G^-1 C.
  Eigen::Matrix2d g;
  g << n, se_(0), se_(0), see_(0, 0);
  Eigen::Matrix<double, 2, kE + 1> c;
  c.row(0) = se_.transpose();
  c.row(1) = see_.row(0);
  ad_ += see_ - c.transpose() * g.inverse() * c;
  ++windows_;
  if (std::fabs(turn_4th_) >= kSelfCalMinTurnRad) ++turning_;
  samples_ += samples_in_window_;
  blocks_ += n_;
  return Status::ok;
}

PickoffSelfCalResult PickoffSelfCalibration::solve(double max_kappa) const {
  PickoffSelfCalResult r;
  r.windows = windows_;
  r.samples = samples_;
  r.turning_windows = turning_;
  const int dof = blocks_ - windows_ - kE;
  const int dof_quad = blocks_ - windows_ - kQ;
  // The per-window decay fit: W more parameters, nu's column gone.
  const int dof_detrended = blocks_ - 2 * windows_ - (kE - 1);
  if (windows_ < 2 || dof_detrended <= 0) return r;
  const Eigen::Matrix<double, kE, kE> n_e = ae_.topLeftCorner<kE, kE>();
  const Eigen::Matrix<double, kQ, kQ> n_q = aq_.topLeftCorner<kQ, kQ>();
  r.kappa_2 = conditioning_of<kE>(n_e).kappa_2;
  r.kappa_2_quad = conditioning_of<kQ>(n_q).kappa_2;
  if (turning_ == 0 || !(r.kappa_2 <= max_kappa) || !(r.kappa_2_quad <= max_kappa)) {
    r.status = Status::ill_conditioned;
    return r;
  }
  const AugmentedFit<kE> e = fit_augmented<kE, kE + 1>(ae_, 0);
  const AugmentedFit<kQ> q = fit_augmented<kQ, kQ + 1>(aq_, 0);
  const AugmentedFit<kE - 1> d = fit_augmented<kE - 1, kE + 1>(ad_, 1);
  const double var = e.rss / dof;
  const double var_q = q.rss / dof_quad;
  const LevelPattern l =
      level_pattern(e.p(kRho), e.p(kBh), e.n_inv(kRho, kRho) * var, e.n_inv(kBh, kBh) * var);
  if (!l.held) {
    r.status = Status::ill_conditioned;  // not a pickoff map the model holds for
    return r;
  }
  r.status = Status::ok;
  r.nu_per_s = e.p(0);
  r.dnu_c_per_s = e.p(1);
  r.dnu_s_per_s = e.p(2);
  r.dnu_c_sigma_per_s = std::sqrt(e.n_inv(1, 1) * var);
  r.dnu_s_sigma_per_s = std::sqrt(e.n_inv(2, 2) * var);
  r.gain = l.gain;
  r.gain_sigma = l.gain_sigma;
  r.misalignment_rad = l.misalignment_rad;
  r.misalignment_sigma_rad = l.misalignment_sigma_rad;
  r.level_8th_c = e.p(kHc);
  r.level_8th_s = e.p(kHs);
  r.dw_c_rad_s = q.p(0);
  r.dw_s_rad_s = q.p(1);
  r.phase_rad = q.p(kPhi);
  r.phase_sigma_rad = std::sqrt(q.n_inv(kPhi, kPhi) * var_q);
  r.residual_rms = std::sqrt(var);
  // The per-window decay test.
  const double extra = static_cast<double>(windows_ - 1);
  r.decay_f = ((e.rss - d.rss) / extra) / (d.rss / dof_detrended);
  r.decay_f_limit = 1.0 + kSelfCalDecaySigmas * std::sqrt(2.0 / extra);
  r.decay_consistent = r.decay_f <= r.decay_f_limit;
  // The decay test's fit: its columns are the level fit's without nu.
  const double var_d = d.rss / dof_detrended;
  const LevelPattern ld =
      level_pattern(d.p(kRho - 1), d.p(kBh - 1), d.n_inv(kRho - 1, kRho - 1) * var_d,
                    d.n_inv(kBh - 1, kBh - 1) * var_d);
  if (ld.held) {
    r.per_window_gain = ld.gain;
    r.per_window_gain_sigma = ld.gain_sigma;
    r.per_window_misalignment_rad = ld.misalignment_rad;
    r.per_window_misalignment_sigma_rad = ld.misalignment_sigma_rad;
  }
  r.per_window_dnu_c_per_s = d.p(0);
  r.per_window_dnu_s_per_s = d.p(1);
  r.per_window_dnu_c_sigma_per_s = std::sqrt(d.n_inv(0, 0) * var_d);
  r.per_window_dnu_s_sigma_per_s = std::sqrt(d.n_inv(1, 1) * var_d);
  return r;
}

void PickoffSelfCalibration::refer_to_applied(const PickoffSelfCalResult& applied) {
  if (applied.status != Status::ok) return;
  const double rho = rho_of_gain(applied.gain);
  VecE de = VecE::Zero();
  de(kRho) = rho;
  de(kBh) = std::sin(2.0 * applied.misalignment_rad) / (2.0 * std::sqrt(1.0 - rho * rho));
  de(kHc) = applied.level_8th_c;
  de(kHs) = applied.level_8th_s;
  subtract_from_observation<kE + 1>(ae_, de);
  subtract_from_observation<kE + 1>(ad_, de);
  VecQ dq = VecQ::Zero();
  dq(kPhi) = applied.phase_rad;
  subtract_from_observation<kQ + 1>(aq_, dq);
}

double damping_anisotropy_disagreement_sigmas(const PickoffSelfCalResult& r, const ParamVector& p,
                                              double sigma_dnu_c_per_s, double sigma_dnu_s_per_s) {
  if (r.status != Status::ok) return 0.0;
  const auto z = [](double a, double b, double sa, double sb) {
    const double s = std::hypot(sa, sb);
    return s > 0.0 ? std::fabs(a - b) / s : 0.0;
  };
  // Where one decay rate does not hold, the fit with a rate per window.
  const bool one = r.decay_consistent;
  const double c = one ? r.dnu_c_per_s : r.per_window_dnu_c_per_s;
  const double s = one ? r.dnu_s_per_s : r.per_window_dnu_s_per_s;
  const double sc = one ? r.dnu_c_sigma_per_s : r.per_window_dnu_c_sigma_per_s;
  const double ss = one ? r.dnu_s_sigma_per_s : r.per_window_dnu_s_sigma_per_s;
  return std::max(z(p(kDnuC), c, sigma_dnu_c_per_s, sc), z(p(kDnuS), s, sigma_dnu_s_per_s, ss));
}

double readout_pattern_sigmas(const PickoffSelfCalResult& r) {
  if (r.status != Status::ok) return 0.0;
  const auto z = [](double x, double sigma) { return sigma > 0.0 ? std::fabs(x) / sigma : 0.0; };
  if (!r.decay_consistent) {
    return std::max(z(r.per_window_gain, r.per_window_gain_sigma),
                    z(r.per_window_misalignment_rad, r.per_window_misalignment_sigma_rad));
  }
  return std::max(z(r.gain, r.gain_sigma), z(r.misalignment_rad, r.misalignment_sigma_rad));
}

double readout_phase_sigmas(const PickoffSelfCalResult& r) {
  if (r.status != Status::ok || !(r.phase_sigma_rad > 0.0)) return 0.0;
  return std::fabs(r.phase_rad) / r.phase_sigma_rad;
}

double readout_phase_drift_share(const PickoffSelfCalResult& r, const ParamVector& p) {
  // Every output frame (the firmware's model check): sqrt, not hypot (no
  // overflow at these magnitudes, a fraction of the cost).
  const double removed = std::sqrt(p(kDnuC) * p(kDnuC) + p(kDnuS) * p(kDnuS));
  if (r.status != Status::ok || !(removed > 0.0)) return 0.0;
  return 2.0 * std::fabs(p(kNu) * r.phase_rad) / removed;
}

}  // namespace hrg::est
