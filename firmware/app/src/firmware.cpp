// SPDX-License-Identifier: MIT
#include "firmware/app/firmware.hpp"

#include <cmath>

namespace hrg::fw::app {

namespace {

bool is_identity_electronics(const Calibration& cal) {
  return cal.pickoff_y_gain == 0.0 && cal.pickoff_y_phase_rad == 0.0 &&
         cal.pickoff_y_misalignment_rad == 0.0 && cal.feedthrough_x_re_v_per_v == 0.0 &&
         cal.feedthrough_x_im_v_per_v == 0.0 && cal.feedthrough_y_re_v_per_v == 0.0 &&
         cal.feedthrough_y_im_v_per_v == 0.0;
}

bool significant(const est::PickoffSelfCalResult& r, double n_sigma) {
  return std::fabs(r.gain) > n_sigma * r.gain_sigma ||
         std::fabs(r.misalignment_rad) > n_sigma * r.misalignment_sigma_rad;
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
  estimator_.set_known_gap(cal.gap_eps_p, cal.gap_eps_q);
  guard_.applied(source, calibration_crc(cal), identity, gyro_.status().chain.t_s,
                 estimator_.health(), checking());
  return true;
}

bool Firmware::checking() const {
  return gyro_.config().identify ? gyro_.scheduler().campaign_done() : estimator_.health().solved;
}

void Firmware::self_calibrate() {
  const est::PickoffSelfCalResult& r = estimator_.pickoff_self_calibration();
  // Once per fresh solve, never inside a window (the identifier restarts).
  if (r.samples == self_cal_samples_seen_ || gyro_.status().mode != Mode::operate) return;
  self_cal_samples_seen_ = r.samples;
  if (r.status != est::Status::ok || !significant(r, kSelfCalSignificance) ||
      self_cal_.rounds >= kMaxSelfCalRounds) {
    return;
  }
  // The estimate is the residual map seen through the correction in force:
  // the gains compose, the misalignments add.
  Calibration next = cfg_.calibration;
  next.pickoff_y_gain = (1.0 + next.pickoff_y_gain) * (1.0 + r.gain) - 1.0;
  next.pickoff_y_misalignment_rad += r.misalignment_rad;
  if (!apply_calibration(next, CalibrationSource::online)) return;
  ++self_cal_.rounds;
  self_cal_.applied = r;
  self_cal_.applied_s = gyro_.status().chain.t_s;
  // Every window so far was taken through the old correction.
  estimator_.restart();
  gyro_.restart_identification();
  self_cal_samples_seen_ = 0;
}

void Firmware::judge_calibration() {
  if (!guard_.judge(estimator_.health(), checking(), gyro_.status().chain.t_s)) return;
  // The chain goes back to the raw pickoffs; the verdict stays reported.
  chain_.clear_electronics_correction();
  cfg_.calibration = kIdentityCalibration;
  estimator_.set_known_gap(0.0, 0.0);
}

}  // namespace hrg::fw::app
