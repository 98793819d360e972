// SPDX-License-Identifier: MIT
#pragma once

// Conditioning of the identification normal matrix (paper section 5: "the
// product of the norms of the matrix and its inverse", "the ratio of the
// largest to the smallest eigenvalue", and the criteria discussed by Kalitkin,
// Yukhno and Kuzmina, Mat. Modelirovanie 23(2), 2011).
//
// The measures are taken on the Jacobi-scaled matrix D^-1/2 N D^-1/2 (unit
// diagonal), so they do not depend on the units of the parameters: a set of
// windows spread evenly over 4theta gives kappa_2 of a few; windows all at one
// angle make the nu, dnu_C and dnu_S columns nearly parallel and kappa_2 huge.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>

namespace hrg::est {

struct Conditioning {
  double kappa_2{
      std::numeric_limits<double>::infinity()};  // lambda_max / lambda_min (= 2-norm ratio)
  double kappa_1{std::numeric_limits<double>::infinity()};  // ||A||_1 ||A^-1||_1
  // Hadamard ratio prod_i ||row_i||_2 / |det A| >= 1 (Kalitkin et al.): 1 for
  // orthogonal rows, grows as rows become dependent. Cheap: no eigenvalues.
  double hadamard{std::numeric_limits<double>::infinity()};
};

// Conditioning of a symmetric positive semi-definite K x K matrix. A zero or
// negative diagonal entry gives infinite measures. No heap.
template <int K>
Conditioning conditioning_of(const Eigen::Matrix<double, K, K>& n) {
  Conditioning c;
  using Mat = Eigen::Matrix<double, K, K>;
  using Vec = Eigen::Matrix<double, K, 1>;
  const Vec d = n.diagonal();
  if (!(d.minCoeff() > 0) || !n.allFinite()) return c;
  const Vec s = d.cwiseSqrt().cwiseInverse();
  const Mat a = s.asDiagonal() * n * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Mat> eig(a, Eigen::EigenvaluesOnly);
  const double lmin = eig.eigenvalues().minCoeff();
  const double lmax = eig.eigenvalues().maxCoeff();
  if (lmin > 0) c.kappa_2 = lmax / lmin;
  const double det = a.determinant();
  if (std::abs(det) > 0) {
    c.hadamard = a.rowwise().norm().prod() / std::abs(det);
    const Mat inv = a.inverse();
    c.kappa_1 = a.cwiseAbs().colwise().sum().maxCoeff() * inv.cwiseAbs().colwise().sum().maxCoeff();
  }
  return c;
}

}  // namespace hrg::est
