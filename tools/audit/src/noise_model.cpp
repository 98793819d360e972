// SPDX-License-Identifier: MIT
#include "noise_model.hpp"

#include <algorithm>
#include <cmath>

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
  return ar;
}

double whitened_chi2(const Dataset& d, const std::vector<double>& res, const ArNoise& ar) {
  double chi2 = 0.0;
  std::size_t k0 = 0;
  for (const auto& seg : d.free) {
    for (std::size_t b = 0; b < seg.n_blocks; ++b) {
      for (std::size_t c = 0; c < 4; ++c) {
        const double r = res[k0 + 4 * b + c];
        if (ar.orders[c].empty()) {
          chi2 += r * r;
          continue;
        }
        const auto& o = ar.orders[c][std::min<std::size_t>(b, ar.orders[c].size() - 1)];
        double e = r;
        for (std::size_t l = 1; l <= o.coef.size(); ++l)
          e -= o.coef[l - 1] * res[k0 + 4 * (b - l) + c];
        chi2 += e * e / o.var;
      }
    }
    k0 += 4 * seg.n_blocks;
  }
  for (std::size_t i = k0; i < res.size(); ++i)
    chi2 += res[i] * res[i];
  return chi2;
}

}  // namespace hrg::audit::detail
