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
// (fw::EstimatorPort::thermal_damping_reading); the pickoff
// self-calibration's whole map (est::whole_estimate: the map in force
// composed with the residual it reads through it, so referred to the raw
// pickoffs). HRG_CAL_READINGS carries them (fw::app::Firmware::estimates()
// fills them), and an hrg-recording's header holds them as `pump_edge_*`,
// `damping_check_*` and `self_cal_*` keys (hrg sim from its run, hrg
// can-decode from the bus).
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
  // The y pickoff map against x in the calibration's convention
  // (dsp/pickoff_correction.hpp), each part with its 1 sigma; only where the
  // self-calibration's solve is ok and one decay rate holds across its
  // windows (what the firmware itself would apply).
  bool pickoff = false;
  double pickoff_gain = 0.0;  // g (-)
  double pickoff_gain_sigma = 0.0;
  double pickoff_misalignment_rad = 0.0;  // b, physical
  double pickoff_misalignment_sigma_rad = 0.0;
  double pickoff_phase_rad = 0.0;  // phi, y lags x
  double pickoff_phase_sigma_rad = 0.0;
};

}  // namespace hrg::fw::can
