// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

#include "dsp/pickoff_correction.hpp"

namespace hrg::fw::can {

// The firmware's own readings of what a calibration holds, beside the
// audit's (tools/audit/README.md, "--calibration"): the switch-off step
// check's residual feedthrough (fw::PumpEdgeStatus) referred to the raw
// pickoffs, on top of the feedthrough in force while its edges were read;
// the damping model check's thermal damping
// (fw::EstimatorPort::thermal_damping_reading). HRG_CAL_READINGS carries
// them (fw::app::Firmware::estimates() fills them), and an hrg-recording's
// header holds them as `pump_edge_*` and `damping_check_*` keys (hrg sim
// from its run, hrg can-decode from the bus).
struct FirmwareEstimates {
  bool feedthrough = false;  // at least one switch-off edge measured
  uint32_t edges = 0;        // switch-offs measured since the correction last changed
  dsp::FeedthroughCoefficients<double> feedthrough_residual_v_per_v{};
  dsp::FeedthroughCoefficients<double> feedthrough_in_force_v_per_v{};
  double feedthrough_sigma_v_per_v = 0.0;    // per part, from the fits' noise
  double feedthrough_scatter_v_per_v = 0.0;  // per part, from the edges' spread
  double in_force_s = 0.0;                   // how long the correction read through was in force
  bool thermal_damping = false;              // the damping model check has a reading
  double thermal_damping_per_c = 0.0;
  double thermal_damping_sigma_per_c = 0.0;
};

}  // namespace hrg::fw::can
