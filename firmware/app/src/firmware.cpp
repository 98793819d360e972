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

// The resonator part: the estimator's regressors and drift use it.
bool is_identity_resonator(const Calibration& cal) {
  return cal.thermal_frequency_ppm_per_c == 0.0 && cal.thermal_damping_per_c == 0.0 &&
         cal.duffing_hz_per_v2 == 0.0 && cal.electrostatic_spring_hz_per_v2 == 0.0 &&
         cal.nonlinear_damping_per_v2 == 0.0;
}

bool has_feedthrough(const Calibration& cal) {
  return cal.feedthrough_x_re_v_per_v != 0.0 || cal.feedthrough_x_im_v_per_v != 0.0 ||
         cal.feedthrough_y_re_v_per_v != 0.0 || cal.feedthrough_y_im_v_per_v != 0.0;
}

bool significant(const est::PickoffSelfCalResult& r, double n_sigma) {
  return std::fabs(r.gain) > n_sigma * r.gain_sigma ||
         std::fabs(r.misalignment_rad) > n_sigma * r.misalignment_sigma_rad ||
         std::fabs(r.phase_rad) > n_sigma * r.phase_sigma_rad;
}

// The estimate's information has grown by `factor` since `before` (every
// parameter's variance divided by it at least).
bool better_by(const est::PickoffSelfCalResult& r, const est::PickoffSelfCalResult& before,
               double factor) {
  const auto shrunk = [factor](double now, double then) {
    return now * now * factor <= then * then;
  };
  return shrunk(r.gain_sigma, before.gain_sigma) &&
         shrunk(r.misalignment_sigma_rad, before.misalignment_sigma_rad) &&
         shrunk(r.phase_sigma_rad, before.phase_sigma_rad);
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
  estimator_.set_resonator_model(cal);
  estimator_.set_known_gap(cal.gap_eps_p, cal.gap_eps_q);
  gyro_.restart_pump_edge_check();
  guard_.applied(source, calibration_crc(cal), identity && is_identity_resonator(cal),
                 has_feedthrough(cal), gyro_.status().chain.t_s, estimator_.health(), checking());
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
  // Nothing while one decay rate does not hold across the windows: a damping
  // that changes between them reads as a level pattern.
  if (r.status != est::Status::ok || !r.decay_consistent || self_cal_.rounds >= kMaxSelfCalRounds) {
    return;
  }
  // First an estimate that stands out of its noise; then the residual of
  // every window so far (re-referred through what is in force) whenever it
  // stands out, or the information behind it has doubled.
  const bool apply = significant(r, kSelfCalSignificance) ||
                     (self_cal_.rounds > 0 && better_by(r, self_cal_.applied, 2.0));
  if (!apply) return;
  // The estimate is the residual map seen through the correction in force:
  // the gains compose, the misalignments and the phases add.
  Calibration next = cfg_.calibration;
  next.pickoff_y_gain = (1.0 + next.pickoff_y_gain) * (1.0 + r.gain) - 1.0;
  next.pickoff_y_misalignment_rad += r.misalignment_rad;
  next.pickoff_y_phase_rad += r.phase_rad;
  if (!apply_calibration(next, CalibrationSource::online)) return;
  ++self_cal_.rounds;
  self_cal_.applied = r;
  self_cal_.applied_s = gyro_.status().chain.t_s;
  // The model's windows were taken through the old correction: it starts
  // again; the self-calibration keeps its windows, re-referred.
  estimator_.restart_after_correction(r);
  gyro_.restart_identification();
}

void Firmware::judge_calibration() {
  const GyroStatus& st = gyro_.status();
  if (!guard_.judge(estimator_.health(), checking(), st.chain.t_s, st.pump_edge.verdict)) return;
  // The chain goes back to the raw pickoffs; the verdict stays reported.
  chain_.clear_electronics_correction();
  cfg_.calibration = kIdentityCalibration;
  estimator_.set_resonator_model(kIdentityCalibration);
  gyro_.restart_pump_edge_check();
  estimator_.set_known_gap(0.0, 0.0);
}

}  // namespace hrg::fw::app
