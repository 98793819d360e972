// SPDX-License-Identifier: MIT
#pragma once

// Matrix exponential by scaling and squaring of a Taylor series. The series
// is summed to 20 terms after scaling the norm below 0.5, so the truncation
// error (0.5^21 / 21!) is far below double rounding; the propagators of both
// resonator models are built from it.

#include <Eigen/Dense>
#include <cmath>

namespace hrg::sim::detail {

template <typename Matrix>
Matrix expm(const Matrix& a) {
  const double norm = a.cwiseAbs().rowwise().sum().maxCoeff();
  int squarings = 0;
  if (norm > 0.5) squarings = static_cast<int>(std::ceil(std::log2(norm / 0.5)));
  const Matrix scaled = a / std::ldexp(1.0, squarings);
  Matrix result = Matrix::Identity(a.rows(), a.cols());
  Matrix term = Matrix::Identity(a.rows(), a.cols());
  for (int k = 1; k <= 20; ++k) {
    term = (term * scaled) / static_cast<double>(k);
    result += term;
  }
  for (int i = 0; i < squarings; ++i)
    result = result * result;
  return result;
}

}  // namespace hrg::sim::detail
