// SPDX-License-Identifier: MIT
#pragma once

namespace hrg::fw {

// What the estimator reports about its own state (the window scheduler ends
// its campaign on it; the telemetry reports it).
struct EstimatorHealth {
  bool solved = false;     // a solution exists
  double condition = 0.0;  // condition number of H^T H (max/min eigenvalue)
  double coverage = 0.0;   // share of 4 theta bins with data, 0..1
};

}  // namespace hrg::fw
