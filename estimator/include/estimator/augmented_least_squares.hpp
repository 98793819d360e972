// SPDX-License-Identifier: MIT
#pragma once

// Least squares on augmented normal equations [N b; b' yy] (columns first,
// the observation last), the form the window checks accumulate: fixed-size
// Eigen, no heap.

#include <Eigen/Cholesky>
#include <algorithm>

namespace hrg::est {

// A window's raw sums [sum v, sum v v'] of n rows to its contribution with
// the window's own offset removed (every column centred within the window).
template <int N>
Eigen::Matrix<double, N, N> centred(const Eigen::Matrix<double, N, 1>& m,
                                    const Eigen::Matrix<double, N, N>& mm, double n) {
  return mm - m * m.transpose() / n;
}

// The fit restricted to columns [first, first + K): solution, inverse of N,
// residual sum of squares.
template <int K>
struct AugmentedFit {
  Eigen::Matrix<double, K, 1> p;
  Eigen::Matrix<double, K, K> n_inv;
  double rss;
};

template <int K, int A>
AugmentedFit<K> fit_augmented(const Eigen::Matrix<double, A, A>& aug, int first) {
  const Eigen::Matrix<double, K, K> n = aug.template block<K, K>(first, first);
  const Eigen::Matrix<double, K, 1> b = aug.template block<K, 1>(first, A - 1);
  const Eigen::LDLT<Eigen::Matrix<double, K, K>> ldlt(n);
  AugmentedFit<K> f;
  f.p = ldlt.solve(b);
  f.n_inv = ldlt.solve(Eigen::Matrix<double, K, K>::Identity());
  f.rss = std::max(0.0, aug(A - 1, A - 1) - f.p.dot(b));
  return f;
}

}  // namespace hrg::est
