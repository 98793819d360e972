// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

namespace hrg::fw {

// What the estimator reports about its own state (the window scheduler ends
// its campaign on it; the telemetry reports it).
struct EstimatorHealth {
  bool solved = false;     // a solution exists
  double condition = 0.0;  // condition number of H^T H (max/min eigenvalue)
  double coverage = 0.0;   // share of 4 theta bins with data, 0..1
  // The model check: the last window's residual against the model in force,
  // over the fit's own residual (1: the model holds), and how many windows
  // were checked so far.
  double window_misfit = 0.0;
  uint32_t windows_checked = 0;
  // A control-loop drift the estimator measured and added is no longer
  // added (est::Estimator::pump_drift_lost): the compensated output misses it.
  bool control_drift_lost = false;
  // Standard errors between the model's damping anisotropy and the one the
  // pickoff self-identification solves with the pickoff level patterns
  // alongside (est::damping_anisotropy_disagreement_sigmas; 0 while either
  // has nothing to say): large when the model took a readout pattern for
  // damping.
  double readout_damping_sigmas = 0.0;
  // Standard errors the pickoff self-identification's gain or misalignment
  // (the larger) stands from zero (est::readout_pattern_sigmas; 0 under
  // the same conditions): the readout's own 4 theta pattern in the measured
  // amplitude, which the D_Phi fits would read as drift.
  double readout_pattern_sigmas = 0.0;
  // The pickoff self-identification's phase lag: standard errors from zero
  // (est::readout_phase_sigmas), and the drift it adds, 2 nu |phi|, over the
  // model's anisotropy drift (est::readout_phase_drift_share; 0 without a
  // model). A phase the correction in force leaves drifts the output by a
  // 4 theta pattern no model holds.
  double readout_phase_sigmas = 0.0;
  double readout_phase_drift_share = 0.0;
  // The pump's part of D_Phi is in use (its online fit usable, or a known
  // gap standing in for it): withholding D_Phi then withholds a drift.
  bool pump_drift_in_use = false;
};

}  // namespace hrg::fw
