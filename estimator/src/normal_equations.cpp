// SPDX-License-Identifier: MIT
#include <estimator/normal_equations.hpp>

#include <Eigen/Cholesky>
#include <array>
#include <cmath>

namespace hrg::est {

namespace {

template <int K>
using Idx = std::array<int, K>;

// Solves the block `idx` of N p = b (other parameters fixed at `fixed`), with
// Jacobi scaling for the conditioning and the solve.
template <int K>
Status solve_block(const AugmentedMatrix& m, const Idx<K>& idx, const ParamVector& fixed,
                   double max_kappa, Eigen::Matrix<double, K, 1>& x,
                   Eigen::Matrix<double, K, K>& n_inv, Conditioning& cond) {
  Eigen::Matrix<double, K, K> n;
  Eigen::Matrix<double, K, 1> b;
  for (int i = 0; i < K; ++i) {
    b(i) = m(idx[i], kParams);
    for (int j = 0; j < kParams; ++j) {
      bool inside = false;
      for (int k = 0; k < K; ++k)
        inside = inside || idx[k] == j;
      if (!inside) b(i) -= m(idx[i], j) * fixed(j);
    }
    for (int j = 0; j < K; ++j)
      n(i, j) = m(idx[i], idx[j]);
  }
  cond = conditioning_of<K>(n);
  if (!(cond.kappa_2 <= max_kappa)) return Status::ill_conditioned;
  const Eigen::Matrix<double, K, 1> s = n.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::Matrix<double, K, K> a = s.asDiagonal() * n * s.asDiagonal();
  const Eigen::LDLT<Eigen::Matrix<double, K, K>> ldlt(a);
  x = s.asDiagonal() * ldlt.solve(s.asDiagonal() * b);
  n_inv = s.asDiagonal() * ldlt.solve(Eigen::Matrix<double, K, K>::Identity()) * s.asDiagonal();
  return x.allFinite() ? Status::ok : Status::ill_conditioned;
}

template <int K>
void finish(const AugmentedMatrix& m, double dof, const Idx<K>& idx,
            const Eigen::Matrix<double, K, 1>& x, const Eigen::Matrix<double, K, K>& n_inv,
            Solution& out) {
  out.p.setZero();
  for (int i = 0; i < K; ++i)
    out.p(idx[i]) = x(i);
  // RSS = y'y - 2 p'b + p'N p over the full model with the unsolved entries 0.
  const ParamVector b = m.block<kParams, 1>(0, kParams);
  const ParamMatrix n = m.block<kParams, kParams>(0, 0);
  const double rss = m(kParams, kParams) - 2.0 * out.p.dot(b) + out.p.dot(n * out.p);
  const double var = dof > 0 && rss > 0 ? rss / dof : 0.0;
  out.sigma_hat_v = std::sqrt(var);
  out.covariance.setZero();
  for (int i = 0; i < K; ++i)
    for (int j = 0; j < K; ++j)
      out.covariance(idx[i], idx[j]) = var * n_inv(i, j);
}

constexpr Idx<5> kAll{kNu, kDnuC, kDnuS, kDwC, kDwS};
constexpr Idx<3> kDamping{kNu, kDnuC, kDnuS};
constexpr Idx<3> kSplit{kNu, kDwC, kDwS};

}  // namespace

void NormalEquations::reset() {
  m_.setZero();
  rows_ = intercepts_ = windows_ = 0;
  have_window_ = false;
  coverage_s_.fill(0);
}

void NormalEquations::add_window(const WindowContribution& w) {
  double decay = 1.0;
  if (config_.forgetting_time_s > 0 && have_window_ && w.t_end_s > t_last_s_)
    decay = std::exp(-(w.t_end_s - t_last_s_) / config_.forgetting_time_s);
  m_ = decay * m_ + w.info;
  rows_ = decay * rows_ + w.rows;
  intercepts_ = decay * intercepts_ + w.intercepts;
  windows_ = decay * windows_ + 1.0;
  for (int i = 0; i < kCoverageBins; ++i)
    coverage_s_[i] = decay * coverage_s_[i] + w.coverage_s[i];
  t_last_s_ = w.t_end_s;
  have_window_ = true;
}

Solution NormalEquations::solve(Variant v) const {
  Solution out;
  out.variant = v;
  if (windows_ < config_.min_windows) return out;
  const ParamVector zero = ParamVector::Zero();
  switch (v) {
    case Variant::joint: {
      Eigen::Matrix<double, 5, 1> x;
      Eigen::Matrix<double, 5, 5> ni;
      out.status = solve_block<5>(m_, kAll, zero, config_.max_kappa_2, x, ni, out.cond);
      if (out.accepted()) finish<5>(m_, rows_ - intercepts_ - 5, kAll, x, ni, out);
      return out;
    }
    case Variant::damping_only:
    case Variant::split_only: {
      const Idx<3>& idx = v == Variant::damping_only ? kDamping : kSplit;
      Eigen::Matrix<double, 3, 1> x;
      Eigen::Matrix<double, 3, 3> ni;
      out.status = solve_block<3>(m_, idx, zero, config_.max_kappa_2, x, ni, out.cond);
      if (out.accepted()) finish<3>(m_, rows_ - intercepts_ - 3, idx, x, ni, out);
      return out;
    }
    case Variant::alternating: break;
  }
  // Eq. 18 (damping with the split known) then eq. 19 (split with the damping
  // known), each a 3x3 solve with the other block moved to the right side.
  ParamVector p = ParamVector::Zero();
  Eigen::Matrix<double, 3, 1> x;
  Eigen::Matrix<double, 3, 3> ni;
  Conditioning cd, cs;
  for (int it = 1; it <= config_.alternating_max_iterations; ++it) {
    const ParamVector prev = p;
    ParamVector fixed = p;
    out.status = solve_block<3>(m_, kDamping, fixed, config_.max_kappa_2, x, ni, cd);
    if (!out.accepted()) {
      out.cond = cd;
      return out;
    }
    for (int i = 0; i < 3; ++i)
      p(kDamping[i]) = x(i);
    fixed = p;
    out.status = solve_block<3>(m_, kSplit, fixed, config_.max_kappa_2, x, ni, cs);
    if (!out.accepted()) {
      out.cond = cs;
      return out;
    }
    for (int i = 0; i < 3; ++i)
      p(kSplit[i]) = x(i);
    out.iterations = it;
    if ((p - prev).norm() <= config_.alternating_tolerance * p.norm()) break;
  }
  // The fixed point is the joint solution; its covariance is the joint one.
  Eigen::Matrix<double, 5, 1> xj;
  Eigen::Matrix<double, 5, 5> nij;
  const Status sj = solve_block<5>(m_, kAll, zero, config_.max_kappa_2, xj, nij, out.cond);
  if (sj != Status::ok) {
    out.status = sj;
    return out;
  }
  Eigen::Matrix<double, 5, 1> xp = p;
  finish<5>(m_, rows_ - intercepts_ - 5, kAll, xp, nij, out);
  out.status =
      out.iterations < config_.alternating_max_iterations ? Status::ok : Status::not_converged;
  return out;
}

ParamMatrix NormalEquations::cramer_rao_bound(double sigma_v) const {
  const ParamMatrix n = m_.block<kParams, kParams>(0, 0);
  const Conditioning c = conditioning_of<kParams>(n);
  if (!std::isfinite(c.kappa_2)) return ParamMatrix::Zero();
  const ParamVector s = n.diagonal().cwiseSqrt().cwiseInverse();
  const ParamMatrix a = s.asDiagonal() * n * s.asDiagonal();
  const Eigen::LDLT<ParamMatrix> ldlt(a);
  return sigma_v * sigma_v *
         (s.asDiagonal() * ldlt.solve(ParamMatrix::Identity()) * s.asDiagonal());
}

Conditioning NormalEquations::conditioning() const {
  return conditioning_of<kParams>(m_.block<kParams, kParams>(0, 0).eval());
}

int NormalEquations::least_covered_bin() const {
  int best = 0;
  for (int i = 1; i < kCoverageBins; ++i)
    if (coverage_s_[i] < coverage_s_[best]) best = i;
  return best;
}

}  // namespace hrg::est
