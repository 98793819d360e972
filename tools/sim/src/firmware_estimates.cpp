// SPDX-License-Identifier: MIT
#include <cmath>

#include "sim_run/run.hpp"

namespace hrg::sim_run {

FirmwareEstimates firmware_estimates(const fw::PumpEdgeStatus& edges,
                                     const fw::app::CalibrationStatus& guard,
                                     const fw::Calibration& loaded,
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
  // The check scales the whole damping change k - 1 by its factor: with a
  // nonlinear term beside the thermal one the factor is not the thermal
  // coefficient's alone, so nothing is said.
  const double beta = loaded.thermal_damping_per_c;
  if (guard.damping_model && guard.damping_factor_sigma > 0.0 && beta != 0.0 &&
      loaded.nonlinear_damping_per_v2 == 0.0) {
    e.thermal_damping = true;
    e.thermal_damping_per_c = guard.damping_factor * beta;
    e.thermal_damping_sigma_per_c = guard.damping_factor_sigma * std::fabs(beta);
  }
  return e;
}

}  // namespace hrg::sim_run
