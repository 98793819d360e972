// SPDX-License-Identifier: MIT
#include "noise_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <utility>

#include <Eigen/Dense>

namespace hrg::audit::detail {

namespace {

// Normal equations of r_t on its lags 1..kMaxOrder for one channel, pooled
// over the segments, on the rows that have every lag (a common sample, so
// that the orders are compared on the same data).
struct LagSums {
  static constexpr int kP = ArNoise::kMaxOrder;
  Eigen::Matrix<double, kP + 1, kP + 1> m = Eigen::Matrix<double, kP + 1, kP + 1>::Zero();
  double n = 0.0;
};

LagSums lag_sums(const Dataset& d, const std::vector<double>& res, std::size_t channel) {
  LagSums s;
  std::size_t k0 = 0;
  Eigen::Matrix<double, LagSums::kP + 1, 1> v;
  for (const auto& seg : d.free) {
    for (std::size_t b = LagSums::kP; b < seg.n_blocks; ++b) {
      for (int l = 0; l <= LagSums::kP; ++l)
        v(l) = res[k0 + 4 * (b - static_cast<std::size_t>(l)) + channel];
      s.m.noalias() += v * v.transpose();
      s.n += 1.0;
    }
    k0 += 4 * seg.n_blocks;
  }
  return s;
}

void fit_scale_var(const Dataset& d, const std::vector<double>& res, ArNoise& ar);

// The excitation segments' observation groups in `res` after the free-decay
// residuals (frequency, balance, angle drift; model.hpp's evaluate()), each
// as [first, end) in time order; empty when `res` holds none or another
// layout.
std::vector<std::pair<std::size_t, std::size_t>> forced_groups(const Dataset& d, std::size_t n_free,
                                                               std::size_t n_res) {
  std::size_t n_bal = 0, n_ang = 0;
  for (const auto& f : d.forced) {
    n_bal += f.balance_sigma_per_s > 0.0 ? 1 : 0;
    n_ang += f.angle_sigma_rad_s > 0.0 ? 1 : 0;
  }
  if (n_res != n_free + d.forced.size() + n_bal + n_ang || d.forced.empty()) return {};
  const std::size_t b0 = n_free + d.forced.size(), a0 = b0 + n_bal;
  return {{n_free, b0}, {b0, a0}, {a0, n_res}};
}

// Least-squares lag-1 coefficient of the excitation groups' residuals,
// pooled, taken when BIC prefers it over none and it is positive: slow
// noise raises the level of slow shapes, and a negative estimate (chance on
// a few dozen segments) would lower their noise below the white level.
double fit_forced_rho(const Dataset& d, const std::vector<double>& res, std::size_t n_free) {
  double s00 = 0.0, s01 = 0.0, s11 = 0.0, n = 0.0;
  for (const auto& [first, end] : forced_groups(d, n_free, res.size())) {
    for (std::size_t i = first + 1; i < end; ++i) {
      s00 += res[i] * res[i], s01 += res[i] * res[i - 1], s11 += res[i - 1] * res[i - 1];
      n += 1.0;
    }
  }
  if (n < 10.0 || !(s11 > 0.0) || !(s00 > 0.0)) return 0.0;
  const double rho = s01 / s11;
  const double var1 = (s00 - rho * s01) / n, var0 = s00 / n;
  const bool taken = var1 > 0.0 && n * std::log(var1 / var0) + std::log(n) < 0.0;
  if (std::getenv("HRG_AUDIT_DEBUG"))
    std::fprintf(stderr, "excitation lag-1 %.3f over %.0f pairs (%s)\n", rho, n,
                 taken ? "taken" : "not taken");
  return taken && rho > 0.0 ? std::min(rho, 0.95) : 0.0;
}

}  // namespace

ArNoise fit_ar_noise(const Dataset& d, const std::vector<double>& res) {
  ArNoise ar;
  std::size_t n_free = 0;
  for (const auto& seg : d.free)
    n_free += 4 * seg.n_blocks;
  if (res.size() < n_free) return ar;
  for (std::size_t c = 0; c < 4; ++c) {
    const LagSums s = lag_sums(d, res, c);
    if (s.n < 50.0) continue;
    double best_bic = 0.0;
    std::vector<ArNoise::Order> all;
    std::size_t best = 0;
    for (int p = 0; p <= LagSums::kP; ++p) {
      double var = s.m(0, 0) / s.n;
      Eigen::VectorXd a;
      if (p > 0) {
        const Eigen::MatrixXd h = s.m.block(1, 1, p, p);
        const Eigen::VectorXd g = s.m.block(1, 0, p, 1);
        a = h.ldlt().solve(g);
        var = (s.m(0, 0) - g.dot(a)) / s.n;
      }
      if (!(var > 0.0)) break;
      const double bic = s.n * std::log(var) + p * std::log(s.n);
      all.push_back({std::vector<double>(a.data(), a.data() + p), var});
      if (p == 0 || bic < best_bic) best_bic = bic, best = all.size() - 1;
    }
    all.resize(best + 1);
    ar.orders[c] = std::move(all);
  }
  fit_scale_var(d, res, ar);
  ar.forced_rho = fit_forced_rho(d, res, n_free);
  return ar;
}

namespace {

// The whitened residuals of one channel of one free segment (blocks from
// residual index k0): each block's prediction error over its innovation sd,
// the first blocks predicted with the lags they have.
void innovations(const std::vector<double>& res, std::size_t k0, std::size_t n_blocks,
                 std::size_t c, const ArNoise& ar, std::vector<double>& e) {
  e.resize(n_blocks);
  for (std::size_t b = 0; b < n_blocks; ++b) {
    const double r = res[k0 + 4 * b + c];
    if (ar.orders[c].empty()) {
      e[b] = r;
      continue;
    }
    const auto& o = ar.orders[c][std::min<std::size_t>(b, ar.orders[c].size() - 1)];
    double v = r;
    for (std::size_t l = 1; l <= o.coef.size(); ++l)
      v -= o.coef[l - 1] * res[k0 + 4 * (b - l) + c];
    e[b] = v / std::sqrt(o.var);
  }
}

// Orthonormal Haar transform of `a` (overwritten): f(scale, c^2, detail) for
// every coefficient, the details of scale j (differences of the means of
// 2^(j-1) blocks), the unpaired remainders and the last mean at the scale
// above the level they stand for. The squares add up to sum a^2.
template <class F>
void haar(std::vector<double>& a, F&& f) {
  constexpr double kR = std::numbers::sqrt2 / 2.0;
  int level = 0;
  while (a.size() > 1) {
    const int scale = std::min(level + 1, ArNoise::kScales);
    if (a.size() % 2 == 1) f(scale, a.back() * a.back(), false);
    const std::size_t m = a.size() / 2;
    for (std::size_t k = 0; k < m; ++k) {
      const double dk = kR * (a[2 * k] - a[2 * k + 1]);
      a[k] = kR * (a[2 * k] + a[2 * k + 1]);
      f(scale, dk * dk, true);
    }
    a.resize(m);
    ++level;
  }
  if (!a.empty()) f(std::min(level + 1, ArNoise::kScales), a[0] * a[0], false);
}

// Least Haar details of a scale for its variance to be estimated.
constexpr double kMinScaleCount = 16.0;

// Variance of the whitened residuals' Haar details per pickoff and scale,
// kept where it stands 3 standard errors above the white level 1; a scale
// with too few details takes the one below it.
void fit_scale_var(const Dataset& d, const std::vector<double>& res, ArNoise& ar) {
  std::array<std::array<double, ArNoise::kScales + 1>, 2> sum{}, cnt{};
  std::vector<double> e;
  std::size_t k0 = 0;
  for (const auto& seg : d.free) {
    for (std::size_t c = 0; c < 4; ++c) {
      innovations(res, k0, seg.n_blocks, c, ar, e);
      haar(e, [&](int j, double c2, bool detail) {
        if (!detail) return;
        sum[c / 2][static_cast<std::size_t>(j)] += c2;
        cnt[c / 2][static_cast<std::size_t>(j)] += 1.0;
      });
    }
    k0 += 4 * seg.n_blocks;
  }
  for (std::size_t p = 0; p < 2; ++p) {
    auto& lambda = ar.scale_var[p];
    std::size_t first = 0, last = 0;  // last estimated scale, first of the run above 1 up to it
    for (std::size_t j = 1; j <= ArNoise::kScales && cnt[p][j] >= kMinScaleCount; ++j) {
      const double v = sum[p][j] / cnt[p][j];
      lambda[j] = v > 1.0 + 3.0 * std::sqrt(2.0 / cnt[p][j]) ? v : 1.0;
      if (lambda[j] == 1.0) first = 0;
      if (lambda[j] > 1.0 && first == 0) first = j;
      last = j;
    }
    // Coarser scales have too few details to be estimated: the variance
    // grows on as it grew from the white level over the run of scales above
    // it up to the last estimated one (at most 2x per scale, 1/f noise's law
    // for Haar details); one scale above the white level alone (3 standard
    // errors of chance among a dozen scales) is carried on, not grown.
    const bool run = first != 0 && last > first;
    const double growth =
        run ? std::clamp(std::pow(lambda[last], 1.0 / static_cast<double>(last - first + 1)), 1.0,
                         2.0)
            : 1.0;
    for (std::size_t j = last + 1; j <= ArNoise::kScales; ++j)
      lambda[j] = lambda[j - 1] * growth;
  }
  if (std::getenv("HRG_AUDIT_DEBUG")) {
    for (std::size_t p = 0; p < 2; ++p) {
      std::fprintf(stderr, "scales p%zu:", p);
      for (std::size_t j = 1; j <= ArNoise::kScales; ++j)
        std::fprintf(stderr, " %.2f(%.0f,%.2f)", ar.scale_var[p][j], cnt[p][j],
                     cnt[p][j] > 0 ? sum[p][j] / cnt[p][j] : 0.0);
      std::fprintf(stderr, "\n");
    }
  }
}

}  // namespace

double whitened_chi2(const Dataset& d, const std::vector<double>& res, const ArNoise& ar) {
  double chi2 = 0.0;
  std::vector<double> e;
  std::size_t k0 = 0;
  for (const auto& seg : d.free) {
    for (std::size_t c = 0; c < 4; ++c) {
      innovations(res, k0, seg.n_blocks, c, ar, e);
      const auto& lambda = ar.scale_var[c / 2];
      haar(e, [&](int j, double c2, bool) { chi2 += c2 / lambda[static_cast<std::size_t>(j)]; });
    }
    k0 += 4 * seg.n_blocks;
  }
  const auto groups = forced_groups(d, k0, res.size());
  if (groups.empty() || ar.forced_rho == 0.0) {
    for (std::size_t i = k0; i < res.size(); ++i)
      chi2 += res[i] * res[i];
    return chi2;
  }
  // AR(1) filter of unit gain from one segment to the next (the fastest
  // shape, alternating): slow noise only adds to the weights' level, at slow
  // shapes, by up to ((1 + rho) / (1 - rho))^2 for a constant; the first of
  // each group at the filter's stationary variance.
  const double rho = ar.forced_rho, g2 = (1.0 + rho) * (1.0 + rho);
  for (const auto& [first, end] : groups) {
    chi2 += res[first] * res[first] * (1.0 - rho) / (1.0 + rho);
    for (std::size_t i = first + 1; i < end; ++i) {
      const double v = res[i] - rho * res[i - 1];
      chi2 += v * v / g2;
    }
  }
  return chi2;
}

double slow_offset_chi2(const Dataset& d, const std::vector<double>& res) {
  std::size_t n_free = 0;
  for (const auto& seg : d.free)
    n_free += 4 * seg.n_blocks;
  const auto groups = forced_groups(d, n_free, res.size());
  if (groups.empty()) return 0.0;
  constexpr int kShapes = 8;
  Eigen::Matrix<double, kShapes, kShapes> n = Eigen::Matrix<double, kShapes, kShapes>::Zero();
  Eigen::Matrix<double, kShapes, 1> g = Eigen::Matrix<double, kShapes, 1>::Zero();
  // Group g's observations are the segments with a weight there, in order.
  auto weight = [](const ForcedSegment& f, std::size_t group) {
    return group == 0 ? f.sigma_rad_s : group == 1 ? f.balance_sigma_per_s : f.angle_sigma_rad_s;
  };
  for (std::size_t grp = 0; grp < 3; ++grp) {
    std::size_t i = groups[grp].first;
    for (const auto& f : d.forced) {
      const double w = weight(f, grp);
      if (!(w > 0.0) || i >= groups[grp].second) continue;
      Eigen::Matrix<double, kShapes, 1> j;
      for (int c = 0; c < kShapes; ++c)
        j(c) = f.per_offset[grp][static_cast<std::size_t>(c)] / w;
      n.noalias() += j * j.transpose();
      g += j * res[i++];
    }
  }
  if (!(n.trace() > 0.0)) return 0.0;
  // Shapes a recording cannot tell apart (a pickoff the pattern never
  // reaches) are dropped by the pseudo-inverse rather than fitted twice.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kShapes, kShapes>> es(n);
  const auto& ev = es.eigenvalues();
  double chi2 = 0.0;
  for (int k = 0; k < kShapes; ++k) {
    if (!(ev(k) > 1e-9 * ev(kShapes - 1))) continue;
    const double p = es.eigenvectors().col(k).dot(g);
    chi2 += p * p / ev(k);
  }
  return chi2;
}

}  // namespace hrg::audit::detail
