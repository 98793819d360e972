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

constexpr int kE = kSelfCalColumns;
constexpr int kEFit = kSelfCalParams;
constexpr int kQ = kSelfCalQuadColumns;
constexpr int kQFit = kSelfCalQuadParams;
// Columns of the level-of-E row.
constexpr int kRho = 3;
constexpr int kBh = 4;
constexpr int kHc = 5;
constexpr int kHs = 6;
constexpr int kKc = 7;
constexpr int kKs = 8;
constexpr int kMc = 9;
constexpr int kMs = 10;
// Columns of the quadrature row.
constexpr int kPhi = 2;
constexpr int kQSlope = 3;
constexpr int kQNc = 4;
constexpr int kQNs = 5;
constexpr int kQAr = 6;
constexpr int kQAs = 7;

// The transform of an augmented state that subtracts sum_j d_j z_j from the
// observation (y' = y - d.z) and turns the column pair (i, i + 1) into a
// frame turned by `turn_rad` (z' = R' z: the coefficients read R(-turn) of
// theirs); applied as A' = T A T', exact on the accumulated sums.
template <int A>
void re_refer(Eigen::Matrix<double, A, A>& aug, const Eigen::Matrix<double, A, 1>& d, int i,
              double turn_rad) {
  Eigen::Matrix<double, A, A> t = Eigen::Matrix<double, A, A>::Identity();
  t.row(A - 1) -= d.transpose();
  const double c = std::cos(turn_rad);
  const double s = std::sin(turn_rad);
  t(i, i) = c;
  t(i, i + 1) = s;
  t(i + 1, i) = -s;
  t(i + 1, i + 1) = c;
  aug = t * aug * t.transpose();
}

// rho (the 4theta coefficient of ln E) of a gain mismatch and back.
double rho_of_gain(double g) {
  const double k = (1.0 + g) * (1.0 + g);
  return (k - 1.0) / (k + 1.0);
}

// The pickoff gain and misalignment of a fit's 4theta pair (rho_f, bh_f)
// and its variances; `held` false outside the map the model holds for.
struct LevelPattern {
  bool held = false;
  double gain = 0.0;
  double gain_sigma = 0.0;
  double misalignment_rad = 0.0;
  double misalignment_sigma_rad = 0.0;
};

LevelPattern level_pattern(double rho_f, double bh_f, double var_rho_f, double var_bh_f) {
  LevelPattern l;
  // The 4theta harmonic of -ln(1 + u) is 2 beta where u has A = 2 beta /
  // (1 + beta^2): the map's pair is the fitted one over 1 + |w|^2 (header).
  // The sigmas scale with it (their change through |w|^2 is O(beta^2) of them).
  const double scale = 1.0 / (1.0 + 0.25 * rho_f * rho_f + bh_f * bh_f);
  const double rho = rho_f * scale;
  const double bh = bh_f * scale;
  const double var_rho = var_rho_f * scale * scale;
  const double var_bh = var_bh_f * scale * scale;
  if (!(std::fabs(rho) < 0.5)) return l;
  const double cos_rho = std::sqrt(1.0 - rho * rho);
  const double sin2b = 2.0 * bh / cos_rho;
  if (!(std::fabs(sin2b) < 0.5)) return l;
  l.held = true;
  // rho = (k - 1)/(k + 1) with k = (1 + g)^2: 1 + g = sqrt((1 + rho)/(1 - rho)).
  l.gain = std::sqrt((1.0 + rho) / (1.0 - rho)) - 1.0;
  l.gain_sigma = std::sqrt(var_rho) / ((1.0 - rho) * cos_rho);
  l.misalignment_rad = 0.5 * std::asin(sin2b);
  l.misalignment_sigma_rad = std::sqrt(var_bh) / (cos_rho * std::cos(2.0 * l.misalignment_rad));
  return l;
}

// What the map does to the damping terms the fit reads (measured frame):
// the anisotropy acts on the true r_t, s_t, which the map's boost moves by
// (rho - r u, -2 bh - s u) to first order (u = rho r - 2 bh s), so
// (ln E)' gains -2 dnu.(r_t - r) = C + 2 [m-pattern]: a constant,
// C = -rho dnu_C + 2 bh dnu_S, read as nu - C/2, and an 8theta rate
// pattern, m_c = -(rho dnu_C + 2 bh dnu_S), m_s = -(rho dnu_S - 2 bh dnu_C)
// (on the columns -2 int (r^2 - s^2)/2, -2 int rs).
struct DampingCrossTerms {
  double nu_shift_per_s;
  double m_c_per_s;
  double m_s_per_s;
};

DampingCrossTerms damping_cross_terms(double rho, double bh, double dnu_c, double dnu_s) {
  return {0.5 * (rho * dnu_c - 2.0 * bh * dnu_s), -(rho * dnu_c + 2.0 * bh * dnu_s),
          -(rho * dnu_s - 2.0 * bh * dnu_c)};
}

// The same for the quadrature row: the split acts at the true angle,
// x_t - x = -rho s - 2 bh r (the boost; the turn by 2b aside), which adds
// -2 (rho s + 2 bh r)(dw_C r + dw_S s) to (Q/E)': a slope
// -(rho dw_S + 2 bh dw_C) and an 8theta rate pattern on int (r^2 - s^2)/2,
// int rs; and the level u multiplies the quadrature, Q/E ~ (1 + u) q_t:
// u q = rho r q - 2 bh s q.
struct SplitCrossTerms {
  double slope_per_s;
  double n_c_per_s;
  double n_s_per_s;
};

SplitCrossTerms split_cross_terms(double rho, double bh, double dw_c, double dw_s) {
  return {-(rho * dw_s + 2.0 * bh * dw_c), -2.0 * (2.0 * bh * dw_c - rho * dw_s),
          -2.0 * (rho * dw_c + 2.0 * bh * dw_s)};
}

// The quadrature row's fit of dw_C, dw_S, phi with the map's cross terms
// held at those of the level row's (rho, bh) and the fitted split (d, their
// values on the columns): once for the split, once more with it.
struct QuadratureFit {
  AugmentedFit<kQFit> fit;
  PickoffSelfCalibration::VecQ held;
};

QuadratureFit fit_quadrature(const PickoffSelfCalibration::AugQ& aq, double rho, double bh) {
  QuadratureFit q{fit_augmented<kQFit, kQ + 1>(aq, 0), PickoffSelfCalibration::VecQ::Zero()};
  for (int pass = 0; pass < 2; ++pass) {
    const SplitCrossTerms x = split_cross_terms(rho, bh, q.fit.p(0), q.fit.p(1));
    q.held << 0.0, 0.0, 0.0, x.slope_per_s, x.n_c_per_s, x.n_s_per_s, rho, -2.0 * bh, 0.0;
    PickoffSelfCalibration::AugQ a = aq;
    re_refer<kQ + 1>(a, q.held, 0, 0.0);
    q.fit = fit_augmented<kQFit, kQ + 1>(a, 0);
  }
  return q;
}

// The level harmonics of w = wr + i wi (header): 2w, 2w^2, -(2/3) w^3 on
// the columns, w^2 and w^3 written out (no <complex> in the freestanding build).
LevelHarmonics harmonics_of_w(double wr, double wi) {
  const double w2r = wr * wr - wi * wi;
  const double w2i = 2.0 * wr * wi;
  const double w3r = w2r * wr - w2i * wi;
  const double w3i = w2r * wi + w2i * wr;
  LevelHarmonics h;
  h.rho_f = 2.0 * wr;
  h.bh_f = wi;
  h.h_c = 2.0 * w2r;
  h.h_s = -2.0 * w2i;
  h.k_c = -2.0 / 3.0 * w3r;
  h.k_s = 2.0 / 3.0 * w3i;
  return h;
}

// The level row's fit (the common decay rate's, and the decay test's with a
// rate per window) of the free columns, with the 12theta level terms held
// at those of the fitted 4theta pair (w = rho_f/2 + i bh_f) and the 8theta
// rate terms at those of it and the fitted dnu: once, once more with them.
struct LevelFit {
  AugmentedFit<kEFit> common;
  AugmentedFit<kEFit - 1> per_window;
  PickoffSelfCalibration::VecE held;
};

LevelFit fit_level(const PickoffSelfCalibration::AugE& ae, const PickoffSelfCalibration::AugE& ad) {
  LevelFit l{fit_augmented<kEFit, kE + 1>(ae, 0), fit_augmented<kEFit - 1, kE + 1>(ad, 1),
             PickoffSelfCalibration::VecE::Zero()};
  for (int pass = 0; pass < 2; ++pass) {
    const double rho_f = l.common.p(kRho);
    const double bh_f = l.common.p(kBh);
    const LevelHarmonics h = harmonics_of_w(0.5 * rho_f, bh_f);
    const DampingCrossTerms x = damping_cross_terms(rho_f, bh_f, l.common.p(1), l.common.p(2));
    l.held(kKc) = h.k_c;
    l.held(kKs) = h.k_s;
    l.held(kMc) = x.m_c_per_s;
    l.held(kMs) = x.m_s_per_s;
    PickoffSelfCalibration::AugE a = ae;
    re_refer<kE + 1>(a, l.held, 1, 0.0);
    l.common = fit_augmented<kEFit, kE + 1>(a, 0);
    a = ad;
    re_refer<kE + 1>(a, l.held, 1, 0.0);
    l.per_window = fit_augmented<kEFit - 1, kE + 1>(a, 1);
  }
  return l;
}

}  // namespace

LevelHarmonics level_harmonics_of(double gain, double misalignment_rad) {
  const double rho = rho_of_gain(gain);
  const double bh = 0.5 * std::sin(2.0 * misalignment_rad) * std::sqrt(1.0 - rho * rho);
  // w = (rho + 2i bh) / (1 + sqrt(1 - A^2)), A^2 = rho^2 + 4 bh^2 (header).
  const double f = 1.0 / (1.0 + std::sqrt(std::max(0.0, 1.0 - rho * rho - 4.0 * bh * bh)));
  return harmonics_of_w(rho * f, 2.0 * bh * f);
}

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
  int_r_ = int_s_ = int_c4_ = int_s4_ = int_c8_ = int_s8_ = 0.0;
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
  // The 8theta columns, (r^2 - s^2)/2 and rs: Re and Im of (r + is)^2 / 2.
  const double r2 = r * r;
  const double s2 = sn * sn;
  const double c8 = 0.5 * (r2 - s2);
  const double s8 = r * sn;
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
    int_c8_ += h * (c8 + last_c8_);
    int_s8_ += h * (s8 + last_s8_);
    turn_4th_ += std::remainder(4.0 * s.theta_A_rad - last_4th_, 2.0 * std::numbers::pi);
  }
  last_4th_ = 4.0 * s.theta_A_rad;
  last_t_ = s.t_s;
  last_r_ = r;
  last_s_ = sn;
  last_c4_ = c4;
  last_s4_ = s4;
  last_c8_ = c8;
  last_s8_ = s8;
  // Level columns up to 12theta (Re and Im of (r + is)^3), then the 8theta
  // rate ones (the header's cross term of the map and the anisotropy).
  VecE v;
  v << -2.0 * (s.t_s - t0_), -2.0 * int_r_, -2.0 * int_s_, -r, 2.0 * sn, c8, s8,
      r * (r2 - 3.0 * s2), sn * (3.0 * r2 - s2), -2.0 * int_c8_, -2.0 * int_s8_, ln_e - y0_;
  VecQ q;
  q << 2.0 * int_s4_, -2.0 * int_c4_, s4, s.t_s - t0_, int_c8_, int_s8_, r * qn, sn * qn, qn;
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
  const int dof = blocks_ - windows_ - kEFit;
  const int dof_quad = blocks_ - windows_ - kQFit;
  // The per-window decay fit: W more parameters, nu's column gone.
  const int dof_detrended = blocks_ - 2 * windows_ - (kEFit - 1);
  if (windows_ < 2 || dof_detrended <= 0) return r;
  const Eigen::Matrix<double, kEFit, kEFit> n_e = ae_.topLeftCorner<kEFit, kEFit>();
  const Eigen::Matrix<double, kQFit, kQFit> n_q = aq_.topLeftCorner<kQFit, kQFit>();
  r.kappa_2 = conditioning_of<kEFit>(n_e).kappa_2;
  r.kappa_2_quad = conditioning_of<kQFit>(n_q).kappa_2;
  if (turning_ == 0 || !(r.kappa_2 <= max_kappa) || !(r.kappa_2_quad <= max_kappa)) {
    r.status = Status::ill_conditioned;
    return r;
  }
  const LevelFit lf = fit_level(ae_, ad_);
  const AugmentedFit<kEFit>& e = lf.common;
  const AugmentedFit<kEFit - 1>& d = lf.per_window;
  const double var = e.rss / dof;
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
  r.level_12th_c = lf.held(kKc);
  r.level_12th_s = lf.held(kKs);
  r.rate_8th_c = lf.held(kMc);
  r.rate_8th_s = lf.held(kMs);
  const QuadratureFit q = fit_quadrature(aq_, e.p(kRho), e.p(kBh));
  r.dw_c_rad_s = q.fit.p(0);
  r.dw_s_rad_s = q.fit.p(1);
  r.quad_slope_per_s = q.held(kQSlope);
  r.quad_rate_8th_c_per_s = q.held(kQNc);
  r.quad_rate_8th_s_per_s = q.held(kQNs);
  r.quad_level_r = q.held(kQAr);
  r.quad_level_s = q.held(kQAs);
  r.phase_rad = q.fit.p(kPhi);
  r.phase_sigma_rad = std::sqrt(q.fit.n_inv(kPhi, kPhi) * q.fit.rss / dof_quad);
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
  // The windows' observations less the applied patterns (y' = y - d.z), and
  // their anisotropy columns turned into the new correction's frame (the
  // misalignment turns the measured 4theta by 2b: z' = R(2b)' z), in one
  // transform of the accumulated sums, A' = T A T'.
  const LevelHarmonics h = level_harmonics_of(applied.gain, applied.misalignment_rad);
  // rho_f, bh_f are rho, bh to O(A^2): the cross terms are first order.
  const DampingCrossTerms x =
      damping_cross_terms(h.rho_f, h.bh_f, applied.dnu_c_per_s, applied.dnu_s_per_s);
  VecE de = VecE::Zero();
  de(0) = x.nu_shift_per_s;
  de(kRho) = h.rho_f;
  de(kBh) = h.bh_f;
  de(kHc) = applied.level_8th_c;
  de(kHs) = applied.level_8th_s;
  de(kKc) = applied.level_12th_c;
  de(kKs) = applied.level_12th_s;
  de(kMc) = applied.rate_8th_c;
  de(kMs) = applied.rate_8th_s;
  const double turn_rad = 2.0 * applied.misalignment_rad;
  re_refer<kE + 1>(ae_, de, 1, turn_rad);
  re_refer<kE + 1>(ad_, de, 1, turn_rad);
  VecQ dq = VecQ::Zero();
  dq(kPhi) = applied.phase_rad;
  dq(kQSlope) = applied.quad_slope_per_s;
  dq(kQNc) = applied.quad_rate_8th_c_per_s;
  dq(kQNs) = applied.quad_rate_8th_s_per_s;
  dq(kQAr) = applied.quad_level_r;
  dq(kQAs) = applied.quad_level_s;
  re_refer<kQ + 1>(aq_, dq, 0, turn_rad);
}

void set_step_terms(PickoffSelfCalResult& step) {
  const LevelHarmonics h = level_harmonics_of(step.gain, step.misalignment_rad);
  step.level_8th_c = h.h_c;
  step.level_8th_s = h.h_s;
  step.level_12th_c = h.k_c;
  step.level_12th_s = h.k_s;
  const DampingCrossTerms x =
      damping_cross_terms(h.rho_f, h.bh_f, step.dnu_c_per_s, step.dnu_s_per_s);
  step.rate_8th_c = x.m_c_per_s;
  step.rate_8th_s = x.m_s_per_s;
  const SplitCrossTerms q = split_cross_terms(h.rho_f, h.bh_f, step.dw_c_rad_s, step.dw_s_rad_s);
  step.quad_slope_per_s = q.slope_per_s;
  step.quad_rate_8th_c_per_s = q.n_c_per_s;
  step.quad_rate_8th_s_per_s = q.n_s_per_s;
  step.quad_level_r = h.rho_f;
  step.quad_level_s = -2.0 * h.bh_f;
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
