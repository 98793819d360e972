// SPDX-License-Identifier: MIT
#include <estimator/drift.hpp>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include <estimator/conditioning.hpp>

namespace hrg::est {

double resonator_drift_rad_s(const ParamVector& p, double theta_A_rad, double aB_over_aA) {
  const double s4 = std::sin(4.0 * theta_A_rad);
  const double c4 = std::cos(4.0 * theta_A_rad);
  const double q = aB_over_aA;
  const double d_nu = p(kDnuC) * s4 - p(kDnuS) * c4;  // nu dmu sin 4(th - th_mu)
  const double w_cos = p(kDwC) * c4 + p(kDwS) * s4;   // dw cos 4(th - th_w)
  return (d_nu * (1.0 + q * q) - 2.0 * q * w_cos) / (1.0 - q * q);
}

ParamVector with_damping_scale(const ParamVector& p, double damping_scale) {
  ParamVector out = p;
  out(kNu) *= damping_scale;
  out(kDnuC) *= damping_scale;
  out(kDnuS) *= damping_scale;
  return out;
}

double known_gap_drift_rad_s(const ParamVector& p, double eps_p, double eps_q, double theta_A_rad,
                             double growth_per_s, double aB_over_aA, double damping_scale) {
  const double s4 = std::sin(4.0 * theta_A_rad);
  const double c4 = std::cos(4.0 * theta_A_rad);
  const double decay = damping_scale * (p(kNu) + p(kDnuC) * c4 + p(kDnuS) * s4) +
                       (p(kDwC) * s4 - p(kDwS) * c4) * aB_over_aA;
  const double kappa = (growth_per_s + decay) / (1.0 + 0.5 * (eps_p * c4 + eps_q * s4));
  return kappa * 0.5 * (eps_q * c4 - eps_p * s4);
}

double KnownGapDrift::step(const ParamVector& p, double eps_p, double eps_q, double t_s,
                           double theta_A_rad, double a_A_v, double aB_over_aA,
                           double damping_scale) {
  if (!std::isfinite(a_A_v) || !(a_A_v > 0.0) || !std::isfinite(t_s)) {
    started_ = false;
    growth_per_s_ = 0.0;
    return 0.0;
  }
  const double ln_a = std::log(a_A_v);
  const double dt = t_s - t_last_s_;
  growth_per_s_ = started_ && dt > 0.0 && dt <= max_gap_s_ ? (ln_a - ln_a_last_) / dt : 0.0;
  started_ = true;
  t_last_s_ = t_s;
  ln_a_last_ = ln_a;
  return known_gap_drift_rad_s(p, eps_p, eps_q, theta_A_rad, growth_per_s_, aB_over_aA,
                               damping_scale);
}

double DriftCompensator::step(double theta_A_rad, double aB_over_aA, double d_phi_rad_s,
                              double dt_s) {
  const double d =
      (have_model_ ? resonator_drift_rad_s(p_, theta_A_rad, aB_over_aA) : 0.0) + d_phi_rad_s;
  return integrate(d, dt_s);
}

double DriftCompensator::integrate(double d_rad_s, double dt_s) {
  const double rate = d_rad_s / k_;
  // Trapezoid on the rate: a model update changes the slope, never the value.
  correction_rad_ += 0.5 * dt_s * ((have_rate_ ? rate_rad_s_ : rate) + rate);
  rate_rad_s_ = rate;
  have_rate_ = true;
  return correction_rad_;
}

void ControlDriftEstimator::restart() {
  acc_ = Block{};
  have_prev_ = false;
  started_ = false;
}

bool ControlDriftEstimator::add_sample(const Sample& s) {
  if (!std::isfinite(s.t_s) || !std::isfinite(s.a_A_v) || !(s.a_A_v > 0) ||
      !std::isfinite(s.a_B_v) || !std::isfinite(s.pump_phase_error_rad) ||
      (started_ && !(s.t_s > t_last_s_))) {
    restart();
    return false;
  }
  if (!started_) {
    started_ = true;
    t_block_start_s_ = s.t_s;
  }
  t_last_s_ = s.t_s;
  acc_.t += s.t_s;
  acc_.aA += s.a_A_v;
  acc_.aB += s.a_B_v;
  acc_.c4 += std::cos(4.0 * s.theta_A_rad);
  acc_.s4 += std::sin(4.0 * s.theta_A_rad);
  acc_.tan_eps += std::tan(s.pump_phase_error_rad);
  acc_.qs += s.quad_force_sin_v_s;
  acc_.qc += s.quad_force_cos_v_s;
  acc_.k += s.damping_scale;
  ++acc_.n;
  if (s.t_s - t_block_start_s_ < config_.block_s) return true;

  Block b = acc_;
  const double inv = 1.0 / b.n;
  b.t *= inv;
  b.aA *= inv;
  b.aB *= inv;
  b.c4 *= inv;
  b.s4 *= inv;
  b.tan_eps *= inv;
  b.qs *= inv;
  b.qc *= inv;
  b.k /= b.n;  // exactly 1 for the seed model (no rounding of inv)
  acc_ = Block{};
  t_block_start_s_ = s.t_s;
  if (have_prev_) {
    // Evaluate at the midpoint of the two block centres.
    const double dt = b.t - prev_.t;
    const double aA = 0.5 * (b.aA + prev_.aA);
    const double aB = 0.5 * (b.aB + prev_.aB);
    const double c4 = 0.5 * (b.c4 + prev_.c4);
    const double s4 = 0.5 * (b.s4 + prev_.s4);
    const double tan_eps = 0.5 * (b.tan_eps + prev_.tan_eps);
    const double k = 0.5 * (b.k + prev_.k);
    const double nu = k * p_(kNu);
    const double dnu = k * (p_(kDnuC) * c4 + p_(kDnuS) * s4);
    const double g = p_(kDwC) * s4 - p_(kDwS) * c4;
    const double fA = (b.aA - prev_.aA) / dt + (nu + dnu) * aA + g * aB;
    const double fB = (b.aB - prev_.aB) / dt + (nu - dnu) * aB - g * aA;
    const double qs = 0.5 * (b.qs + prev_.qs);
    const double qc = 0.5 * (b.qc + prev_.qc);
    const double fA_cos = fA * tan_eps;
    const double fB_cos = (fB - qs) * tan_eps + qc;
    const double d = -fB_cos / aA + (aB / aA) * fA_cos / aA;
    if (!have_estimate_) {
      d_phi_rad_s_ = d;
      d_var_ = 0.0;
      alpha_ = 1.0;
      have_estimate_ = true;
    } else {
      alpha_ = 1.0 - std::exp(-dt / config_.smoothing_s);
      const double innovation = d - d_phi_rad_s_;
      d_phi_rad_s_ += alpha_ * innovation;
      d_var_ += alpha_ * (innovation * innovation * (1.0 - alpha_) - d_var_);
    }
  }
  prev_ = b;
  have_prev_ = true;
  return true;
}

double ControlDriftEstimator::d_phi_sigma_rad_s() const {
  // Variance of a first-order low-pass of independent samples: var a/(2-a).
  // The first blocks (alpha 1) have no spread yet: infinite until then.
  if (!have_estimate_ || !(alpha_ < 1.0)) return std::numeric_limits<double>::infinity();
  return std::sqrt(std::max(d_var_, 0.0) * alpha_ / (2.0 - alpha_));
}

double ControlDriftEstimator::used_d_phi_rad_s() const {
  if (!have_estimate_) return 0.0;
  if (config_.min_sigmas <= 0.0) return d_phi_rad_s_;
  return std::fabs(d_phi_rad_s_) >= config_.min_sigmas * d_phi_sigma_rad_s() ? d_phi_rad_s_ : 0.0;
}

void PumpDriftEstimator::fold_segment() {
  if (seg_blocks_ >= 3) {
    MatR c = seg_s_ - seg_sum_ * seg_sum_.transpose() / seg_blocks_;
    double decay = 1.0;
    if (config_.forgetting_time_s > 0 && have_fold_)
      decay = std::exp(-(t_last_s_ - t_last_fold_s_) / config_.forgetting_time_s);
    m_ = decay * m_ + c * static_cast<double>(config_.block_samples);
    for (MatR& b : batch_)
      b *= decay;
    batch_[segments_ % kBatches] += c * static_cast<double>(config_.block_samples);
    ++segments_;
    fit_s_ = decay * fit_s_ + (t_last_s_ - t0_s_);
    t_last_fold_s_ = t_last_s_;
    have_fold_ = true;
    refresh_fit();
  }
  started_ = false;
  seg_s_.setZero();
  seg_sum_.setZero();
  seg_blocks_ = 0;
  block_.setZero();
  in_block_ = 0;
}

void PumpDriftEstimator::restart() {
  fold_segment();
  w_count_ = 0;  // the pumps before the break are not the ones the next rows see
}

void PumpDriftEstimator::set_model(const ParamVector& p, const ParamMatrix& covariance) {
  p_ = p;
  p_cov_ = covariance;
  if (have_fold_) refresh_fit();
}

Eigen::Matrix<double, 2, kParams> PumpDriftEstimator::model_shift() const {
  // A model off by dp adds dp' J to every y, and the fit (b0, b1, b2) moves
  // by N^-1 [sum I J'] dp (the sums of the rows, m_'s regressor-J block).
  const Eigen::Matrix3d n = m_.topLeftCorner<3, 3>();
  const Eigen::Vector3d s = n.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d a = s.asDiagonal() * n * s.asDiagonal();
  const Eigen::Matrix<double, 3, kParams> x = m_.block<3, kParams>(0, 3);
  const Eigen::Matrix<double, 3, kParams> shift =
      s.asDiagonal() * a.ldlt().solve(s.asDiagonal() * x);
  return shift.bottomRows<2>();
}

PumpDriftEstimator::Mat4 PumpDriftEstimator::with_model(const MatR& m) const {
  // y = L + p' J: the row (I0, I1, I2, y) is t r with t = [I3 0 0; 0 p' 1].
  Eigen::Matrix<double, 4, kRow> t = Eigen::Matrix<double, 4, kRow>::Zero();
  t.topLeftCorner<3, 3>().setIdentity();
  t.block<1, kParams>(3, 3) = p_.transpose();
  t(3, kRow - 1) = 1.0;
  return t * m * t.transpose();
}

bool PumpDriftEstimator::add_sample(const Sample& s) {
  if (!std::isfinite(s.t_s) || !std::isfinite(s.a_A_v) || !(s.a_A_v > 0) ||
      !std::isfinite(s.a_B_v) || !std::isfinite(s.theta_A_rad) || !std::isfinite(s.pump_v) ||
      !(s.pump_v >= 0) || !std::isfinite(s.pump_phase_error_rad) ||
      !std::isfinite(s.damping_scale) ||
      (w_count_ > 0 && !(s.t_s > t_last_s_ && s.t_s - t_last_s_ <= config_.max_sample_gap_s))) {
    restart();
    return false;
  }
  const int lag = std::clamp(config_.pump_lag_samples, 0, kMaxPumpLag);
  const std::size_t n_ring = w_ring_.size();
  w_pos_ = (w_pos_ + 1) % n_ring;
  w_ring_[w_pos_] = s.pump_v * s.pump_v * std::cos(s.pump_phase_error_rad);
  if (w_count_ < lag + 1) ++w_count_;
  if (w_count_ <= lag) {
    t_last_s_ = s.t_s;  // history only: the rows before it saw an unknown pump
    return true;
  }
  const double w = w_ring_[(w_pos_ + n_ring - static_cast<std::size_t>(lag)) % n_ring];
  w_last_ = w;
  const double c4 = std::cos(4.0 * s.theta_A_rad);
  const double s4 = std::sin(4.0 * s.theta_A_rad);
  const double k = s.damping_scale;
  const double q = s.a_B_v / s.a_A_v;
  // Integrands: the three pump regressors and the known decay rate's five
  // (k (nu + dnu_C c4 + dnu_S s4) + (dw_C s4 - dw_S c4) q = p' J').
  VecH h;
  h << w, w * c4, w * s4, k, k * c4, k * s4, q * s4, -q * c4;
  const double ln_a = std::log(s.a_A_v);
  if (!started_) {
    started_ = true;
    t0_s_ = t_last_s_ = s.t_s;
    ln_a0_ = ln_a;
    z_.setZero();
  } else {
    z_ += 0.5 * (s.t_s - t_last_s_) * (h_prev_ + h);
    t_last_s_ = s.t_s;
  }
  h_prev_ = h;
  block_.head<kRow - 1>() += z_;
  block_(kRow - 1) += ln_a - ln_a0_;
  if (++in_block_ == config_.block_samples) {
    const VecR r = block_ / in_block_;
    seg_s_ += r * r.transpose();
    seg_sum_ += r;
    ++seg_blocks_;
    block_.setZero();
    in_block_ = 0;
  }
  if (t_last_s_ - t0_s_ >= config_.segment_s && in_block_ == 0) fold_segment();
  return true;
}

void PumpDriftEstimator::refresh_fit() {
  const Mat4 m = with_model(m_);
  const Eigen::Matrix3d n = m.topLeftCorner<3, 3>();
  kappa_2_ = conditioning_of<3>(n).kappa_2;
  if (fit_s_ >= config_.min_fit_s && kappa_2_ <= config_.max_kappa_2) conditioned_ = true;
  coefficients_.setZero();
  gap_sigmas_ = 0.0;
  if (!valid()) return;
  const Eigen::Vector3d b = m.topRightCorner<3, 1>();
  const Eigen::Vector3d s = n.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d a = s.asDiagonal() * n * s.asDiagonal();
  coefficients_ = s.asDiagonal() * a.ldlt().solve(s.asDiagonal() * b);
  gap_sigmas_ = gap_sigmas_from(Eigen::Vector2d::Zero());
}

double PumpDriftEstimator::kappa_2() const { return kappa_2_; }

bool PumpDriftEstimator::valid() const {
  if (fit_s_ < config_.min_fit_s) return false;
  if (kappa_2_ <= config_.max_kappa_2) return true;
  // Without forgetting the sums only grow: once conditioned, every
  // combination of (b0, b1, b2) stays at least as well determined. Rows at
  // one angle (the parks, a pattern at its equilibrium) raise kappa_2 by
  // informing one combination more, not the others less; cutting the fit
  // there dropped a D_Phi of 16-64 deg/h in the middle of the bias test.
  return conditioned_ && !(config_.forgetting_time_s > 0.0);
}

Eigen::Vector3d PumpDriftEstimator::coefficients() const { return coefficients_; }

double PumpDriftEstimator::d_phi_rad_s(double theta_A_rad) const {
  const Eigen::Vector3d c = coefficients();
  return w_last_ * (c(2) * std::cos(4.0 * theta_A_rad) - c(1) * std::sin(4.0 * theta_A_rad));
}

}  // namespace hrg::est

namespace hrg::est {

double PumpDriftEstimator::gap() const {
  if (!valid()) return 0.0;
  const Eigen::Vector3d c = coefficients();
  return c(0) > 0.0 ? 2.0 * std::hypot(c(1), c(2)) / c(0) : 0.0;
}

namespace {
// (b1, b2) of a 3x3 fit [N b; b' y'y]; false when N is singular.
bool gap_harmonic(const Eigen::Matrix4d& m, Eigen::Vector2d& g) {
  const Eigen::Matrix3d n = m.topLeftCorner<3, 3>();
  if (!(conditioning_of<3>(n).kappa_2 < 1e8)) return false;
  const Eigen::Vector3d s = n.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d a = s.asDiagonal() * n * s.asDiagonal();
  const Eigen::Vector3d x =
      s.asDiagonal() * a.ldlt().solve(s.asDiagonal() * m.topRightCorner<3, 1>());
  g = x.tail<2>();
  return g.allFinite();
}
}  // namespace

double PumpDriftEstimator::gap_sigmas() const { return gap_sigmas_; }

bool PumpDriftEstimator::gap_fit(Eigen::Vector2d& g, Eigen::Matrix2d& cov) const {
  if (!valid() || segments_ < 2 * kBatches) return false;
  if (!gap_harmonic(with_model(m_), g)) return false;
  std::array<Eigen::Vector2d, kBatches> gb;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int j = 0; j < kBatches; ++j) {
    if (!gap_harmonic(with_model(batch_[static_cast<std::size_t>(j)]),
                      gb[static_cast<std::size_t>(j)]))
      return false;
    mean += gb[static_cast<std::size_t>(j)] / kBatches;
  }
  // Covariance of the full fit ~ that of the mean of the batch fits, plus
  // what the model's own uncertainty moves the fit by (model_shift()).
  cov.setZero();
  for (const Eigen::Vector2d& x : gb)
    cov += (x - mean) * (x - mean).transpose();
  cov /= static_cast<double>(kBatches) * (kBatches - 1);
  const Eigen::Matrix<double, 2, kParams> a = model_shift();
  cov += a * p_cov_ * a.transpose();
  return true;
}

double PumpDriftEstimator::gap_sigmas_from(const Eigen::Vector2d& g0,
                                           const Eigen::Matrix2d& g0_covariance) const {
  Eigen::Vector2d g;
  Eigen::Matrix2d cov;
  if (!gap_fit(g, cov)) return 0.0;
  const Eigen::Vector2d dg = g - g0;
  const double m2 = dg.dot((cov + g0_covariance).ldlt().solve(dg));
  return m2 > 0.0 && std::isfinite(m2) ? std::sqrt(m2) : 0.0;
}

}  // namespace hrg::est
