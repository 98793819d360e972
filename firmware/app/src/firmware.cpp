// SPDX-License-Identifier: MIT
#include "firmware/app/firmware.hpp"

namespace hrg::fw::app {

bool Firmware::apply_calibration(const Calibration& cal) {
  if (first_out_of_range(cal) >= 0) return false;
  dsp::PickoffCorrection<double> pickoff;
  if (!pickoff_correction(cal, pickoff)) return false;
  // No electronics part costs nothing: the stage stays off.
  const bool identity = cal.pickoff_y_gain == 0.0 && cal.pickoff_y_phase_rad == 0.0 &&
                        cal.pickoff_y_misalignment_rad == 0.0 &&
                        cal.feedthrough_x_re_v_per_v == 0.0 &&
                        cal.feedthrough_x_im_v_per_v == 0.0 &&
                        cal.feedthrough_y_re_v_per_v == 0.0 && cal.feedthrough_y_im_v_per_v == 0.0;
  if (identity) {
    chain_.clear_electronics_correction();
  } else if (!chain_.set_electronics_correction(pickoff, feedthrough_coefficients(cal))) {
    return false;
  }
  cfg_.calibration = cal;
  return true;
}

}  // namespace hrg::fw::app
