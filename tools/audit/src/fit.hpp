// SPDX-License-Identifier: MIT
#pragma once

// Levenberg-Marquardt on the model's free parameters (forward-difference
// Jacobian, parameters scaled by their typical magnitude).

#include "model.hpp"

namespace hrg::audit::detail {

struct FitResult {
  Params p{};
  Params sigma{};  // 1-sigma from (J^T J)^-1 in noise units (white-noise Cramer-Rao)
  double chi2 = 0.0;
  std::size_t n_res = 0;
  int iterations = 0;
  bool converged = false;
};

FitResult fit(const Dataset& d, const Params& start, const Mask& free, const EvalOptions& o,
              int max_iterations = 30);

}  // namespace hrg::audit::detail
