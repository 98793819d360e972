// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "firmware/can/firmware_estimates.hpp"

namespace hrg::can {

// The firmware's own estimates as an hrg-recording's header keys, the one
// form hrg sim (from its run) and hrg can-decode (from HRG_CAL_READINGS)
// write and hrg audit --calibration reads (tools/audit/README.md):
// pump_edge_edges, pump_edge_{x,y}_{re,im}_v_per_v, pump_edge_sigma_v_per_v,
// pump_edge_scatter_v_per_v, pump_edge_in_force_s,
// pump_edge_in_force_{x,y}_{re,im}_v_per_v when an edge was measured;
// damping_check_thermal_damping_per_c and ..._sigma_per_c when the damping
// model check has a reading; self_cal_gain, self_cal_misalignment_rad,
// self_cal_phase_rad and each one's _sigma (self_cal_gain_sigma,
// self_cal_{misalignment,phase}_sigma_rad) when the pickoff
// self-calibration has a map the firmware stands behind. Nothing else is
// written.
std::vector<std::pair<std::string, std::string>> estimates_header(
    const fw::can::FirmwareEstimates& e);

}  // namespace hrg::can
