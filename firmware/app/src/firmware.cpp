// SPDX-License-Identifier: MIT
#include "firmware/app/firmware.hpp"

namespace hrg::fw::app {

namespace {

bool is_identity_electronics(const Calibration& cal) {
  return cal.pickoff_y_gain == 0.0 && cal.pickoff_y_phase_rad == 0.0 &&
         cal.pickoff_y_misalignment_rad == 0.0 && cal.feedthrough_x_re_v_per_v == 0.0 &&
         cal.feedthrough_x_im_v_per_v == 0.0 && cal.feedthrough_y_re_v_per_v == 0.0 &&
         cal.feedthrough_y_im_v_per_v == 0.0;
}

}  // namespace

bool Firmware::apply_calibration(const Calibration& cal, CalibrationSource source) {
  if (first_out_of_range(cal) >= 0) return false;
  dsp::PickoffCorrection<double> pickoff;
  if (!pickoff_correction(cal, pickoff)) return false;
  // No electronics part costs nothing: the stage stays off.
  const bool identity = is_identity_electronics(cal);
  if (identity) {
    chain_.clear_electronics_correction();
  } else if (!chain_.set_electronics_correction(pickoff, feedthrough_coefficients(cal))) {
    return false;
  }
  cfg_.calibration = cal;
  guard_.applied(source, calibration_crc(cal), identity, gyro_.status().chain.t_s,
                 estimator_.health(), checking());
  return true;
}

bool Firmware::checking() const {
  return gyro_.config().identify ? gyro_.scheduler().campaign_done() : estimator_.health().solved;
}

void Firmware::judge_calibration() {
  if (!guard_.judge(estimator_.health(), checking(), gyro_.status().chain.t_s)) return;
  // The chain goes back to the raw pickoffs; the verdict stays reported.
  chain_.clear_electronics_correction();
  cfg_.calibration = kIdentityCalibration;
}

}  // namespace hrg::fw::app
