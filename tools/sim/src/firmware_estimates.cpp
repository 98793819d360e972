// SPDX-License-Identifier: MIT
#include "sim_run/run.hpp"

namespace hrg::sim_run {

FirmwareEstimates firmware_estimates(const fw::PumpEdgeStatus& edges,
                                     const fw::EstimatorPort::ThermalDampingReading& thermal,
                                     const fw::Calibration& in_force) {
  FirmwareEstimates e;
  // The edges since the last reset were read through the correction in
  // force at the end (a change of it resets the check).
  if (edges.edges > 0) {
    e.feedthrough = true;
    e.feedthrough_residual_v_per_v =
        fw::residual_at_raw_pickoffs(in_force, {edges.x_re, edges.x_im, edges.y_re, edges.y_im});
    e.feedthrough_in_force_v_per_v = fw::feedthrough_coefficients(in_force);
  }
  e.thermal_damping = thermal.valid;
  e.thermal_damping_per_c = thermal.per_c;
  e.thermal_damping_sigma_per_c = thermal.sigma_per_c;
  return e;
}

}  // namespace hrg::sim_run
