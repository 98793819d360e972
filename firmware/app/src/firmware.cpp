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

bool same_electronics(const Calibration& a, const Calibration& b) {
  return a.pickoff_y_gain == b.pickoff_y_gain && a.pickoff_y_phase_rad == b.pickoff_y_phase_rad &&
         a.pickoff_y_misalignment_rad == b.pickoff_y_misalignment_rad &&
         a.feedthrough_x_re_v_per_v == b.feedthrough_x_re_v_per_v &&
         a.feedthrough_x_im_v_per_v == b.feedthrough_x_im_v_per_v &&
         a.feedthrough_y_re_v_per_v == b.feedthrough_y_re_v_per_v &&
         a.feedthrough_y_im_v_per_v == b.feedthrough_y_im_v_per_v;
}

// `cal` without its resonator model (the seed's model instead).
Calibration without_resonator_model(Calibration cal) {
  cal.thermal_frequency_ppm_per_c = 0.0;
  cal.thermal_damping_per_c = 0.0;
  cal.duffing_hz_per_v2 = 0.0;
  cal.electrostatic_spring_hz_per_v2 = 0.0;
  cal.nonlinear_damping_per_v2 = 0.0;
  return cal;
}

bool has_feedthrough(const Calibration& cal) {
  return cal.feedthrough_x_re_v_per_v != 0.0 || cal.feedthrough_x_im_v_per_v != 0.0 ||
         cal.feedthrough_y_re_v_per_v != 0.0 || cal.feedthrough_y_im_v_per_v != 0.0;
}

est::PickoffMap pickoff_map(const Calibration& cal) {
  return {cal.pickoff_y_gain, cal.pickoff_y_misalignment_rad, cal.pickoff_y_phase_rad};
}

Calibration with_pickoff_map(Calibration cal, const est::PickoffMap& m) {
  cal.pickoff_y_gain = m.gain;
  cal.pickoff_y_misalignment_rad = m.misalignment_rad;
  cal.pickoff_y_phase_rad = m.phase_rad;
  return cal;
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
  put_in_force(cal, !same_electronics(cal, cfg_.calibration));
  guard_.applied(source, calibration_crc(cal), identity && is_identity_resonator(cal),
                 has_feedthrough(cal), gyro_.status().chain.t_s, estimator_.health(), checking(),
                 has_damping_model(cal));
  return true;
}

void Firmware::put_in_force(const Calibration& cal, bool electronics_changed) {
  // The sigma belongs to the gap it was given with (the file's at start).
  if (cal.gap_eps_p != cfg_.calibration.gap_eps_p || cal.gap_eps_q != cfg_.calibration.gap_eps_q)
    cfg_.calibration_gap_sigma = {};
  cfg_.calibration = cal;
  estimator_.set_resonator_model(cal);
  const GapSigma& s = cfg_.calibration_gap_sigma;
  estimator_.set_known_gap({cal.gap_eps_p, cal.gap_eps_q, s.eps_p, s.eps_q});
  // The switch-off steps of a signal corrected otherwise start again.
  if (electronics_changed) gyro_.restart_pump_edge_check();
  // A model changed in operation is checked soon, not a check period later.
  gyro_.model_changed();
}

can::FirmwareEstimates Firmware::estimates() const {
  const PumpEdgeStatus& edges = gyro_.status().pump_edge;
  const Calibration& in_force = cfg_.calibration;
  can::FirmwareEstimates e;
  if (edges.edges > 0) {
    e.feedthrough = true;
    e.edges = edges.edges;
    e.feedthrough_residual_v_per_v =
        residual_at_raw_pickoffs(in_force, {edges.x_re, edges.x_im, edges.y_re, edges.y_im});
    e.feedthrough_in_force_v_per_v = feedthrough_coefficients(in_force);
    e.feedthrough_sigma_v_per_v = edges.sigma_v_per_v;
    e.feedthrough_scatter_v_per_v = edges.scatter_v_per_v;
    e.in_force_s = edges.in_force_s;
  }
  const EstimatorPort::ThermalDampingReading thermal = estimator_.thermal_damping_reading();
  e.thermal_damping = thermal.valid;
  e.thermal_damping_per_c = thermal.per_c;
  e.thermal_damping_sigma_per_c = thermal.sigma_per_c;
  // The pickoff map only where the firmware would stand behind it: a
  // damping that changes between the windows reads as a level pattern.
  const est::PickoffSelfCalResult& r = estimator_.pickoff_self_calibration();
  if (r.status == est::Status::ok && r.decay_consistent) {
    const est::PickoffMapEstimate m = est::whole_estimate(pickoff_map(in_force), r);
    e.pickoff = true;
    e.pickoff_gain = m.value.gain;
    e.pickoff_gain_sigma = m.sigma.gain;
    e.pickoff_misalignment_rad = m.value.misalignment_rad;
    e.pickoff_misalignment_sigma_rad = m.sigma.misalignment_rad;
    e.pickoff_phase_rad = m.value.phase_rad;
    e.pickoff_phase_sigma_rad = m.sigma.phase_rad;
  }
  return e;
}

bool Firmware::checking() const {
  return gyro_.config().identify ? gyro_.scheduler().campaign_done() : estimator_.health().solved;
}

void Firmware::self_calibrate() {
  const est::PickoffSelfCalResult& r = estimator_.pickoff_self_calibration();
  // Once per fresh solve, never inside a window (the identifier restarts).
  if (r.samples == self_cal_samples_seen_ || gyro_.status().mode != Mode::operate) return;
  self_cal_samples_seen_ = r.samples;
  const est::PickoffMap in_force = pickoff_map(cfg_.calibration);
  const SelfCalibrationDecision d = self_cal_.decide(r, in_force);
  if (d.action == SelfCalibrationAction::none || !put_self_calibration_in_force(d)) return;
  self_cal_.done(d, r, in_force, gyro_.status().chain.t_s);
  // The model's windows were taken through the old correction: it starts
  // again; the self-calibration keeps its windows, re-referred.
  estimator_.restart_after_correction(d.step);
  gyro_.restart_identification();
}

bool Firmware::put_self_calibration_in_force(const SelfCalibrationDecision& d) {
  const uint32_t crc_withdrawn = guard_.status().crc32;
  if (!apply_calibration(with_pickoff_map(cfg_.calibration, d.target), CalibrationSource::online))
    return false;
  // The map before the rounds is back where they held nothing, as it was
  // before them (not on trial again); what the firmware reports is the
  // withdrawal, where a check window's would go (HRG_STATUS cal_withdrawn,
  // report.json).
  if (d.action == SelfCalibrationAction::withdraw)
    guard_.withdrawn(CalibrationSource::online, crc_withdrawn, gyro_.status().chain.t_s);
  return true;
}

est::PickoffMap Firmware::pickoff_map_to_keep() const {
  const est::PickoffMap in_force = pickoff_map(cfg_.calibration);
  if (!cfg_.online_pickoff_calibration) return in_force;
  return self_cal_.map_to_keep(estimator_.pickoff_self_calibration(), in_force);
}

void Firmware::refer_self_calibration_to_raw(const est::PickoffMap& withdrawn) {
  if (withdrawn == est::PickoffMap{}) return;
  // The self-calibration's windows so far were read through the map
  // withdrawn: mixed with the raw ones after it, its residual would be of
  // neither (a 1 deg phase lag with half of it withdrawn read 0.657 +- 0.003
  // deg).
  est::PickoffSelfCalResult ok;
  ok.status = est::Status::ok;
  estimator_.refer_self_calibration(est::step_between(withdrawn, {}, ok));
}

void Firmware::judge_calibration() {
  judge_calibration_parts();
  const CalibrationStatus& c = guard_.status();
  gyro_.set_calibration_flags({.withdrawn = c.verdict == CalibrationVerdict::withdrawn,
                               .damping_refuted = c.damping_refuted,
                               .gap_refuted = c.gap_refuted});
}

void Firmware::judge_calibration_parts() {
  const GyroStatus& st = gyro_.status();
  const double t_s = st.chain.t_s;
  if (guard_.judge(estimator_.health(), checking(), t_s, st.pump_edge.verdict)) {
    // The chain goes back to the raw pickoffs; the verdict stays reported.
    // A seed's model kept beside a damping part takes over.
    const est::PickoffMap withdrawn = pickoff_map(cfg_.calibration);
    chain_.clear_electronics_correction();
    estimator_.fall_back_to_seed_model();
    put_in_force(kIdentityCalibration, true);
    refer_self_calibration_to_raw(withdrawn);
    return;
  }
  const est::DampingModelCheckResult& d = estimator_.damping_model_check();
  if (d.status == est::Status::ok && d.supported) estimator_.keep_resonator_model();
  if (d.status == est::Status::ok &&
      guard_.judge_damping_model(d.factor, d.factor_sigma, d.refuted, t_s)) {
    // The seed's model from now on, the one identified beside it from the
    // same windows; when none was kept (the check had supported the part
    // before), the model starts again.
    const bool kept = estimator_.seed_model_kept();
    estimator_.fall_back_to_seed_model();
    put_in_force(without_resonator_model(cfg_.calibration), false);
    if (!kept) {
      estimator_.restart_model();
      gyro_.restart_identification();
    }
  }
  if (guard_.judge_gap(estimator_.estimator().known_gap_refuted(), t_s)) {
    // The online fit of the pump's drift for the rest of the run (the
    // estimator has switched to it already; kept across model restarts).
    Calibration no_gap = cfg_.calibration;
    no_gap.gap_eps_p = 0.0;
    no_gap.gap_eps_q = 0.0;
    put_in_force(no_gap, false);
  }
}

}  // namespace hrg::fw::app
