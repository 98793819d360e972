// SPDX-License-Identifier: MIT
#include "sim_run/report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "can/estimates_header.hpp"
#include "firmware/compensation_reason.hpp"
#include "recording/recording.hpp"
#include "recording/recording_writer.hpp"
#include "sim_run/console.hpp"
#include "sim_run/json.hpp"

namespace hrg::sim_run {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDegRad = kPi / 180.0;
constexpr const char* kParamNames[5] = {"nu_per_s", "dnu_c_per_s", "dnu_s_per_s", "dw_c_rad_s",
                                        "dw_s_rad_s"};
constexpr double kRadSToDph = 180.0 / kPi * 3600.0;

// Tolerances of the pass/fail checks, in one place.
constexpr double kTrackSlackFraction = 0.25;  // raw error may differ from the model by this share
constexpr double kTrackFloorDeg = 0.02;       // plus this (noise, the control-loop drift)
constexpr double kAdbReduction = 0.5;         // compensation must at least halve the ADB

void bias_json(JsonWriter& w, const char* key, const BiasFit& f) {
  w.begin_object(key);
  w.number("adb_dph", f.amplitude());
  w.number("mean_dph", f.b0);
  w.number("sin4_dph", f.a_sin4);
  w.number("cos4_dph", f.b_cos4);
  w.number("sigma_mean_dph", f.sigma_b0);
  w.number("residual_rms_dph", f.residual_rms);
  w.boolean("fitted", f.ok);
  // Parks at nearly one 4 theta: adb_dph and mean_dph are not separable,
  // park_mean_dph is the figure (sim_run::BiasFit::degenerate).
  w.boolean("degenerate", f.degenerate());
  w.number("condition", f.condition);
  w.number("span_deg", f.span_rad / kDegRad);
  w.number("park_mean_dph", f.park_mean);
  w.number("sigma_park_mean_dph", f.sigma_park_mean);
  w.end_object();
}
// RMS of the parks' biases, raw and compensated, over the parks with the
// model valid (those the compensated fit holds).
double park_rms(const RunResult& r, bool compensated) {
  double sum2 = 0.0;
  std::size_t n = 0;
  for (const ParkResult& p : r.parks) {
    if (!p.model_valid) continue;
    const double b = compensated ? p.bias_comp_dph : p.bias_raw_dph;
    sum2 += b * b;
    ++n;
  }
  return n > 0 ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0;
}
double raw_park_rms(const RunResult& r) { return park_rms(r, false); }
double compensated_park_rms(const RunResult& r) { return park_rms(r, true); }
}  // namespace

std::string degenerate_parks_note(const BiasFit& f) {
  return fmt(
      "the %zu parks span %.2f deg of pattern angle (%.1f deg of 4 theta); the 4 theta "
      "fit's condition %.3g is above %.0f, so its mean and ADB are not separable: the "
      "mean bias over the parks is %+.4f +- %.4f deg/h",
      f.points, f.span_rad / kDegRad, 4.0 * f.span_rad / kDegRad, f.condition, kMaxBiasFitCondition,
      f.park_mean, f.sigma_park_mean);
}

std::string bias_test_coverage(const RunResult& r) {
  std::string s =
      fmt("the compensated bias is measured on %zu of %zu parks (those with the model "
          "valid throughout",
          r.parks_model_valid, r.parks.size());
  s += r.t_model_valid_s >= 0.0 ? fmt("; valid from %.1f s)", r.t_model_valid_s)
                                : std::string("; the model was never valid)");
  if (r.bias_test_needs_s <= 0.0) return s;
  s += fmt("; this resonator needs a run of at least %.0f s (--duration %.0f)", r.bias_test_needs_s,
           r.bias_test_needs_s);
  if (r.t_model_valid_s >= 0.0 && r.t_bias_goal_s >= 0.0) {
    // The estimate: the same bias test started once the model is valid and
    // its uncertainty has converged to the goal (at least: a longer run
    // parks longer, and a campaign that waits for the parks to cover its
    // 4 theta bins ends later).
    s +=
        fmt(": the bias test started when the model is valid (%.0f s) and its bias "
            "uncertainty is a third of the %.3g deg/h goal (%s%.0f s%s)",
            r.t_model_valid_s, r.bias_goal_dph, r.t_bias_goal_extrapolated ? "about " : "",
            r.t_bias_goal_s, r.t_bias_goal_extrapolated ? ", from its convergence so far" : "");
  }
  return s;
}

bool judge(const RunConfig& job, RunResult& r) {
  r.failures.clear();
  if (!r.reached_operate) r.failures.push_back("the gyro never reached operate");
  if (r.final_mode == fw::Mode::safe || r.final_mode == fw::Mode::fault) {
    r.failures.push_back(std::string("the run ended in ") + fw::to_string(r.final_mode));
  }
  if (r.windows >= 3 && !r.identification.valid) {
    r.failures.push_back("free-decay windows ran but no identification was accepted");
  }
  if (r.reached_operate) {
    const double slack = kTrackSlackFraction * r.drift_bound_deg + kTrackFloorDeg;
    if (std::fabs(r.raw_error_end_deg - r.model_error_end_deg) > slack) {
      r.failures.push_back(
          fmt("raw output error %.4f deg differs from the drift model's %.4f deg "
              "by more than %.4f deg",
              r.raw_error_end_deg, r.model_error_end_deg, slack));
    }
    if (std::fabs(r.comp_error_end_deg) > r.drift_bound_deg + kTrackFloorDeg) {
      r.failures.push_back(fmt("compensated output error %.4f deg exceeds the drift bound %.4f deg",
                               r.comp_error_end_deg, r.drift_bound_deg));
    }
  }
  if (r.model_checks_failed > 0) {
    r.failures.push_back(
        fmt("the drift compensation is not valid: %u check window(s) disagreed "
            "with the model (last misfit %.3g, agreement between %.3g and %.3g); "
            "the output is the raw angle",
            r.model_checks_failed, r.last_window_misfit, job.firmware.gyro.min_window_misfit,
            job.firmware.gyro.max_window_misfit));
  }
  if (r.calibration.verdict == fw::app::CalibrationVerdict::withdrawn) {
    const fw::app::CalibrationStatus& c = r.calibration;
    const std::string before =
        c.misfit_before > 0.0 ? fmt(" and the check before it (%.2f)", c.misfit_before) : "";
    const fw::app::SelfCalibrationStatus& sc = r.self_calibration_applied;
    if (c.source == fw::app::CalibrationSource::online && sc.withdrawn) {
      r.failures.push_back(
          fmt("the online pickoff self-calibration's %u round(s) were withdrawn at %.1f s: "
              "its per-window decay test refutes the one decay rate they were solved with "
              "(F %.3g against %.3g), and its fit with a decay rate per window holds what "
              "they changed at %.2f sigma; those parts of the map before them are in force "
              "and kept",
              sc.rounds, sc.withdrawn_s, sc.withdrawn_decay_f, sc.withdrawn_decay_f_limit,
              sc.withdrawn_support_sigmas));
    } else if (c.edge == fw::PumpEdgeVerdict::step) {
      r.failures.push_back(
          fmt("the %s calibration was withdrawn at %.1f s: the signal it "
              "corrected steps at the pump's switch-offs (its feedthrough "
              "removal is wrong); the pickoffs are read raw",
              fw::app::to_string(c.source), c.judged_s));
    } else {
      r.failures.push_back(
          fmt("the %s calibration was withdrawn at %.1f s: its check window's "
              "misfit %.2f is above the noise (%.1f)%s; the pickoffs are read raw",
              fw::app::to_string(c.source), c.judged_s, c.misfit_after,
              job.firmware.gyro.max_window_misfit, before.c_str()));
    }
  }
  if (r.calibration.damping_refuted) {
    const fw::app::CalibrationStatus& c = r.calibration;
    r.failures.push_back(
        fmt("the calibration's damping model was refuted at %.1f s: the free decays show "
            "%.2f +- %.2f of the damping change it predicts (1 if it held, below 0.5 it "
            "fits worse than none); the seed's model is used and identified again",
            c.damping_refuted_s, c.damping_factor, c.damping_factor_sigma));
  }
  if (r.calibration.gap_refuted) {
    r.failures.push_back(
        fmt("the calibration's gap harmonic was refuted at %.1f s: the online fit of the "
            "pump's drift stands %.1f sigmas of the difference or more away from it (the "
            "fit's and the file's own uncertainty together); the online fit is used",
            r.calibration.gap_refuted_s, job.firmware.estimator.pump.min_gap_sigmas));
  }
  if (r.pump_edge.verdict == fw::PumpEdgeVerdict::step) {
    r.failures.push_back(
        fmt("the drift compensation is not valid: the corrected signal steps by %.3g V "
            "(+- %.2g) at the pump's switch-offs, above the %.3g V it may (an uncorrected "
            "or wrongly corrected drive feedthrough)",
            r.pump_edge.step_v, r.pump_edge.step_sigma_v, r.pump_edge.tolerance_v));
  }
  if (!job.parks.empty() && !r.fit_comp.ok && !r.fit_comp.degenerate()) {
    // Too few parks with the model valid to fit: the compensation is not
    // measured (not "no better than raw"), and the length it needs is said.
    r.failures.push_back(bias_test_coverage(r));
  }
  // Parks at nearly one 4 theta (a long still run): no ADB to compare; the
  // compensation must halve the bias where the parks are.
  const BiasFit& narrow = r.fit_comp.degenerate() ? r.fit_comp : r.fit_raw;
  const bool degenerate = narrow.degenerate();
  if (!job.parks.empty() && degenerate && r.identification.valid &&
      compensated_park_rms(r) > kAdbReduction * raw_park_rms(r)) {
    r.failures.push_back(
        fmt("compensation did not halve the bias at the parked angles (rms %.3f -> %.3f "
            "deg/h; %s)",
            raw_park_rms(r), compensated_park_rms(r), degenerate_parks_note(narrow).c_str()));
  }
  if (!job.parks.empty() && r.fit_raw.ok && r.fit_comp.ok && !degenerate &&
      r.identification.valid && r.fit_comp.amplitude() > kAdbReduction * r.fit_raw.amplitude()) {
    r.failures.push_back(
        fmt("compensation did not halve the angle-dependent bias (%.3f -> %.3f "
            "deg/h)",
            r.fit_raw.amplitude(), r.fit_comp.amplitude()));
  }
  return r.failures.empty();
}

namespace {

// The switch-off step check: the residual feedthrough it measures (V/V per
// volt of pump, against the NCO) and the step at the last edge's pump.
void pump_edge_json(JsonWriter& w, const fw::PumpEdgeStatus& e, const FirmwareEstimates& f) {
  w.begin_object("pump_edge");
  w.string("verdict", fw::to_string(e.verdict));
  w.integer("edges", e.edges);
  w.number("residual_x_re_v_per_v", e.x_re);
  w.number("residual_x_im_v_per_v", e.x_im);
  w.number("residual_y_re_v_per_v", e.y_re);
  w.number("residual_y_im_v_per_v", e.y_im);
  w.number("residual_sigma_v_per_v", e.sigma_v_per_v);
  w.number("residual_scatter_v_per_v", e.scatter_v_per_v);
  w.number("in_force_s", e.in_force_s);
  // The residual at the raw pickoffs and the feedthrough it is on top of
  // (the recording's pump_edge_* keys).
  const auto& r = f.feedthrough_residual_v_per_v;
  const auto& k = f.feedthrough_in_force_v_per_v;
  w.number("raw_residual_x_re_v_per_v", r.x_re);
  w.number("raw_residual_x_im_v_per_v", r.x_im);
  w.number("raw_residual_y_re_v_per_v", r.y_re);
  w.number("raw_residual_y_im_v_per_v", r.y_im);
  w.number("in_force_x_re_v_per_v", k.x_re);
  w.number("in_force_x_im_v_per_v", k.x_im);
  w.number("in_force_y_re_v_per_v", k.y_re);
  w.number("in_force_y_im_v_per_v", k.y_im);
  w.number("step_v", e.step_v);
  w.number("step_sigma_v", e.step_sigma_v);
  w.number("tolerance_v", e.tolerance_v);
  w.end_object();
}

// The calibration's trial: where it came from, the check window that judged
// it (misfits over the fit's own residual), withdrawn or not.
void calibration_json(JsonWriter& w, const fw::app::CalibrationStatus& c,
                      const fw::Calibration& in_force, const FirmwareEstimates& f) {
  w.begin_object("calibration");
  // The pickoff map in force at the end (after a withdrawal: the identity).
  w.number("pickoff_y_gain", in_force.pickoff_y_gain);
  w.number("pickoff_y_phase_deg", in_force.pickoff_y_phase_rad / kDegRad);
  w.number("pickoff_y_misalignment_deg", in_force.pickoff_y_misalignment_rad / kDegRad);
  w.string("source", fw::app::to_string(c.source));
  w.string("verdict", fw::app::to_string(c.verdict));
  w.boolean("feedthrough", c.feedthrough);
  w.boolean("window_agreed", c.window_agreed);
  w.string("edge", fw::to_string(c.edge));
  w.integer("crc32", c.crc32);
  w.number("applied_s", c.applied_s);
  w.number("misfit_before", c.misfit_before);
  w.number("misfit_after", c.misfit_after);
  w.number("judged_s", c.judged_s);
  w.integer("withdrawals", c.withdrawals);
  // The resonator model's damping part (its own check on every window) and
  // the gap harmonic (against the online fit), each refuted or not.
  w.boolean("damping_model", c.damping_model);
  w.boolean("damping_refuted", c.damping_refuted);
  w.number("damping_factor", c.damping_factor);
  w.number("damping_factor_sigma", c.damping_factor_sigma);
  w.number("damping_refuted_s", c.damping_refuted_s);
  w.number("thermal_damping_per_c", in_force.thermal_damping_per_c);
  w.number("nonlinear_damping_per_v2", in_force.nonlinear_damping_per_v2);
  // The damping check's own thermal coefficient (the recording's
  // damping_check_* keys): its factor times the beta given.
  w.boolean("damping_check_thermal", f.thermal_damping);
  w.number("damping_check_thermal_damping_per_c", f.thermal_damping_per_c);
  w.number("damping_check_thermal_damping_sigma_per_c", f.thermal_damping_sigma_per_c);
  w.boolean("gap_refuted", c.gap_refuted);
  w.number("gap_refuted_s", c.gap_refuted_s);
  w.number("gap_eps_p", in_force.gap_eps_p);
  w.number("gap_eps_q", in_force.gap_eps_q);
  w.end_object();
}

const char* solve_status(est::Status s) {
  switch (s) {
    case est::Status::ok: return "ok";
    case est::Status::no_data: return "no_data";
    case est::Status::ill_conditioned: return "ill_conditioned";
    default: return "refused";
  }
}

// The pickoff self-calibration's last solve (est::PickoffSelfCalibration).
// The whole map the firmware reads (the recording's self_cal_* keys: the map
// in force composed with the residual below), absent when it does not
// stand behind one.
void whole_map_json(JsonWriter& w, const FirmwareEstimates& f) {
  w.boolean("whole_valid", f.pickoff);
  if (!f.pickoff) return;
  w.number("whole_gain", f.pickoff_gain);
  w.number("whole_gain_sigma", f.pickoff_gain_sigma);
  w.number("whole_misalignment_rad", f.pickoff_misalignment_rad);
  w.number("whole_misalignment_sigma_rad", f.pickoff_misalignment_sigma_rad);
  w.number("whole_phase_rad", f.pickoff_phase_rad);
  w.number("whole_phase_sigma_rad", f.pickoff_phase_sigma_rad);
}

void self_calibration_json(JsonWriter& w, const est::PickoffSelfCalResult& s,
                           const fw::app::SelfCalibrationStatus& applied,
                           const est::PickoffMap& keep, const FirmwareEstimates& f) {
  w.begin_object("self_calibration");
  whole_map_json(w, f);
  w.integer("rounds_applied", applied.rounds);
  // The rounds taken back when their model was refuted (Firmware::
  // self_calibrate, fw::app::SelfCalibrationRounds): every round then.
  w.integer("rounds_withdrawn", applied.withdrawn ? applied.rounds : 0);
  w.boolean("withdrawn", applied.withdrawn);
  w.number("withdrawn_s", applied.withdrawn_s);
  w.number("withdrawn_decay_f", applied.withdrawn_decay_f);
  w.number("withdrawn_decay_f_limit", applied.withdrawn_decay_f_limit);
  w.number("withdrawn_support_sigmas", applied.withdrawn_support_sigmas);
  // The map kept for the next power-up (Firmware::pickoff_map_to_keep).
  w.number("keep_gain", keep.gain);
  w.number("keep_misalignment_deg", keep.misalignment_rad / kDegRad);
  w.number("keep_phase_deg", keep.phase_rad / kDegRad);
  w.number("last_applied_s", applied.applied_s);
  w.number("last_applied_gain", applied.applied.gain);
  w.number("last_applied_gain_sigma", applied.applied.gain_sigma);
  w.number("last_applied_misalignment_deg", applied.applied.misalignment_rad / kDegRad);
  w.number("last_applied_misalignment_sigma_deg", applied.applied.misalignment_sigma_rad / kDegRad);
  w.number("last_applied_phase_deg", applied.applied.phase_rad / kDegRad);
  w.number("last_applied_phase_sigma_deg", applied.applied.phase_sigma_rad / kDegRad);
  w.number("last_applied_residual_rms", applied.applied.residual_rms);
  w.number("last_applied_kappa", applied.applied.kappa_2);
  // The last solve (after the last round: the residual left).
  w.string("status", solve_status(s.status));
  w.number("gain", s.gain);
  w.number("gain_sigma", s.gain_sigma);
  w.number("misalignment_deg", s.misalignment_rad / kDegRad);
  w.number("misalignment_sigma_deg", s.misalignment_sigma_rad / kDegRad);
  w.number("phase_deg", s.phase_rad / kDegRad);
  w.number("phase_sigma_deg", s.phase_sigma_rad / kDegRad);
  w.number("kappa", s.kappa_2);
  w.number("kappa_quad", s.kappa_2_quad);
  // The per-window decay test (one nu across the windows: F ~ 1).
  w.number("decay_f", s.decay_f);
  w.number("decay_f_limit", s.decay_f_limit);
  w.boolean("decay_consistent", s.decay_consistent);
  // The decay test's fit (a decay rate per window), the readout checks'
  // figures where the test refuses the common one.
  w.number("per_window_gain", s.per_window_gain);
  w.number("per_window_gain_sigma", s.per_window_gain_sigma);
  w.number("per_window_misalignment_deg", s.per_window_misalignment_rad / kDegRad);
  w.number("per_window_misalignment_sigma_deg", s.per_window_misalignment_sigma_rad / kDegRad);
  w.number("per_window_dnu_c_per_s", s.per_window_dnu_c_per_s);
  w.number("per_window_dnu_s_per_s", s.per_window_dnu_s_per_s);
  w.number("per_window_dnu_c_sigma_per_s", s.per_window_dnu_c_sigma_per_s);
  w.number("per_window_dnu_s_sigma_per_s", s.per_window_dnu_s_sigma_per_s);
  w.number("residual_rms", s.residual_rms);
  w.integer("windows", s.windows);
  w.integer("turning_windows", s.turning_windows);
  w.end_object();
}

// The names of the set bits of fw::CompensationReason (none: valid).
std::string compensation_reason_text(uint8_t bits) {
  std::string s;
  for (int i = 0; i < fw::kCompensationReasonBits; ++i) {
    if ((bits >> i & 1u) == 0) continue;
    s += (s.empty() ? "" : ", ") + std::string(fw::kCompensationReasonNames[i]);
  }
  return s.empty() ? std::string("none") : s;
}

// Why the compensation is not valid at the end, the model check against the
// readout's pattern, and D_Phi: whether it stood (not withheld), what was
// added and withheld, and the pump fit's gap harmonic behind it.
void compensation_health_json(JsonWriter& w, const RunResult& r) {
  w.integer("reason_bits", r.compensation_reasons);
  w.begin_array("reasons");
  for (int i = 0; i < fw::kCompensationReasonBits; ++i)
    if ((r.compensation_reasons >> i & 1u) != 0) w.string({}, fw::kCompensationReasonNames[i]);
  w.end_array();
  w.number("readout_damping_sigmas", r.readout_damping_sigmas);
  w.number("readout_pattern_sigmas", r.readout_pattern_sigmas);
  w.number("readout_phase_sigmas", r.readout_phase_sigmas);
  w.number("readout_phase_drift_share", r.readout_phase_drift_share);
  w.begin_object("control_drift");
  const auto withheld = fw::reason_bit(fw::CompensationReason::control_drift_withheld);
  w.boolean("valid", (r.compensation_reasons & withheld) == 0);
  w.number("applied_mean_dph", r.control_drift_mean_dph);
  w.number("withheld_mean_dph", r.control_drift_withheld_mean_dph);
  w.boolean("pump_fit_usable", r.pump_drift_usable);
  w.number("pump_gap", r.pump_gap);
  w.number("pump_gap_sigmas", r.pump_gap_sigmas);
  w.number("pump_eps_p", r.pump_eps_pq_sigma[0]);
  w.number("pump_eps_q", r.pump_eps_pq_sigma[1]);
  w.number("pump_eps_p_sigma", r.pump_eps_pq_sigma[2]);
  w.number("pump_eps_q_sigma", r.pump_eps_pq_sigma[3]);
  w.end_object();
}

void drift_json(JsonWriter& w, const RunResult& r) {
  w.begin_object("drift");
  bias_json(w, "raw", r.fit_raw);
  bias_json(w, "compensated", r.fit_comp);
  bias_json(w, "model", r.fit_model);
  w.integer("parked_angles", static_cast<long long>(r.parks.size()));
  w.integer("parks_model_valid", static_cast<long long>(r.parks_model_valid));
  w.number("t_model_valid_s", r.t_model_valid_s);
  w.number("bias_test_needs_s", r.bias_test_needs_s);
  w.number("bias_goal_dph", r.bias_goal_dph);
  w.number("t_bias_goal_s", r.t_bias_goal_s);
  w.boolean("t_bias_goal_extrapolated", r.t_bias_goal_extrapolated);
  w.number("control_drift_mean_dph", r.control_drift_mean_dph);
  w.begin_array("parks");
  for (const auto& p : r.parks) {
    w.begin_object();
    w.number("theta_deg", p.theta_rad * 180.0 / kPi);
    w.number("raw_dph", p.bias_raw_dph);
    w.number("compensated_dph", p.bias_comp_dph);
    w.number("model_dph", p.bias_model_dph);
    w.boolean("model_valid", p.model_valid);
    w.end_object();
  }
  w.end_array();
  w.end_object();
}

void identification_json(JsonWriter& w, const RunResult& r) {
  w.begin_object("identification");
  w.boolean("accepted", r.identification.valid);
  w.number("condition_number", r.condition);
  w.number("coverage", r.coverage);
  w.integer("windows", r.windows);
  w.integer("windows_accepted", r.windows_accepted);
  w.boolean("campaign_done", r.campaign_done);
  w.number("t_converged_s", r.t_converged_s);
  w.number("noise_sigma_v", r.noise_sigma_v);
  for (int i = 0; i < 5; ++i) {
    w.begin_object(kParamNames[i]);
    w.number("estimate", r.identification.p[i]);
    w.number("sigma", r.identification.sigma[i]);
    w.number("crb_sigma", r.crb_sigma[static_cast<std::size_t>(i)]);
    w.number("truth", r.truth[static_cast<std::size_t>(i)]);
    w.end_object();
  }
  w.end_object();
}

void tracking_json(JsonWriter& w, const RunResult& r) {
  w.begin_object("tracking");
  w.number("t_operate_s", r.t_operate_s);
  w.number("rms_deg", r.tracking_rms_deg);
  w.number("max_deg", r.tracking_max_deg);
  w.number("raw_error_end_deg", r.raw_error_end_deg);
  w.number("compensated_error_end_deg", r.comp_error_end_deg);
  w.number("model_error_end_deg", r.model_error_end_deg);
  w.number("drift_bound_deg", r.drift_bound_deg);
  w.end_object();
}

void executive_json(JsonWriter& w, const RunResult& r) {
  w.begin_object("executive");
  w.string("pacing", r.real_time ? "real_time" : "lockstep");
  if (r.real_time) w.string("realtime_setup", r.realtime_setup);
  w.integer("frames", static_cast<long long>(r.frames.frames));
  w.integer("missed_frames", r.frames.missed_frames);
  w.integer("deadline_misses", r.frames.deadline_misses);
  w.number("max_frame_us", r.frames.max_frame_ns / 1e3);
  w.begin_object("tasks");
  for (const auto& t : r.tasks) {
    w.begin_object(t.name);
    w.integer("rate_hz", t.rate_hz);
    w.number("budget_us", t.budget_ns / 1e3);
    w.number("max_us", t.max_ns / 1e3);
    w.number("mean_us", t.mean_ns / 1e3);
    w.integer("overruns", t.overruns);
    w.integer("slips", t.slips);
    w.end_object();
  }
  w.end_object();
  w.end_object();
}

void allan_json(JsonWriter& w, const RunResult& r) {
  w.number("allan_span_s", r.allan_span_s);
  // The flat bottom of the curve (IEEE 952 bias instability, before the 0.664 factor).
  double adev_min = 0, tau_min = 0;
  for (const auto& p : r.allan) {
    if (adev_min == 0 || p.adev < adev_min) {
      adev_min = p.adev;
      tau_min = p.tau_s;
    }
  }
  w.number("allan_min_dph", adev_min * kRadSToDph);
  w.number("allan_min_tau_s", tau_min);
  w.begin_array("allan_deviation");
  for (const auto& p : r.allan) {
    w.begin_object();
    w.number("tau_s", p.tau_s);
    w.number("adev_dph", p.adev * kRadSToDph);
    w.end_object();
  }
  w.end_array();
}

}  // namespace

std::string report_json(const RunConfig& job, const RunResult& r) {
  JsonWriter w;
  w.begin_object();
  w.string("scenario", job.description);
  w.number("duration_s", r.sim_s);
  w.number("wall_s", r.wall_s);
  w.number("realtime_factor", r.realtime_factor);
  w.number("realtime_factor_cpu", r.realtime_factor_cpu);
  w.number("simulation_share", r.sim_share);
  w.number("simulation_share_cpu", r.sim_share_cpu);
  w.number("excitation_off_fraction", r.excitation_off_fraction);
  w.boolean("passed", r.failures.empty());
  w.begin_array("failures");
  for (const auto& f : r.failures)
    w.string({}, f);
  w.end_array();
  drift_json(w, r);
  w.begin_object("compensation");
  w.boolean("valid", r.compensation_valid);
  w.boolean("applied", r.compensation_applied);
  w.integer("model_checks_failed", r.model_checks_failed);
  w.number("last_window_misfit", r.last_window_misfit);
  compensation_health_json(w, r);
  // The calibration in force (CRC-32 of its canonical form, as hrg
  // calibration-check prints it; that of the identity when none was given).
  w.integer("calibration_crc32", fw::calibration_crc(job.firmware.calibration));
  calibration_json(w, r.calibration, r.final_calibration, r.firmware_estimates);
  pump_edge_json(w, r.pump_edge, r.firmware_estimates);
  self_calibration_json(w, r.self_calibration, r.self_calibration_applied, r.self_calibration_keep,
                        r.firmware_estimates);
  w.end_object();
  identification_json(w, r);
  tracking_json(w, r);
  executive_json(w, r);
  allan_json(w, r);
  w.integer("can_frames", static_cast<long long>(r.can_frames));
  w.string("final_mode", fw::to_string(r.final_mode));
  w.integer("faults_seen", r.faults_seen);
  w.end_object();
  return w.str();
}

namespace {

const std::vector<std::string>& telemetry_columns() {
  static const std::vector<std::string> cols{"t_s",
                                             "cx_v",
                                             "sx_v",
                                             "cy_v",
                                             "sy_v",
                                             "exc",
                                             "pump_v",
                                             "temp_c",
                                             "rate_dps",
                                             "pll_hz",
                                             "quad_v",
                                             "mode",
                                             "theta_deg",
                                             "out_angle_deg",
                                             "true_angle_deg",
                                             "raw_angle_deg",
                                             "true_theta_deg",
                                             "a_a_v",
                                             "a_b_v",
                                             "drift_model_dph",
                                             "drift_true_dph",
                                             "out_valid",
                                             "pattern_cmd",
                                             "comp_valid",
                                             "raw_error_deg",
                                             "out_error_deg",
                                             "comp_reasons",
                                             "readout_damping_sigmas"};
  return cols;
}

// One row's values in telemetry_columns() order.
void telemetry_values(const TelemetryRow& row, std::vector<double>& v) {
  v = {row.t_s,
       row.cx_v,
       row.sx_v,
       row.cy_v,
       row.sy_v,
       double(row.exc),
       row.pump_v,
       row.temp_c,
       row.rate_dps,
       row.pll_hz,
       row.quad_v,
       double(row.mode),
       row.theta_deg,
       row.out_angle_deg,
       row.true_angle_deg,
       row.raw_angle_deg,
       row.true_theta_deg,
       row.a_A_v,
       row.a_B_v,
       row.drift_model_dph,
       row.drift_true_dph,
       double(row.out_valid),
       double(row.pattern_cmd),
       double(row.comp_valid),
       row.raw_error_deg,
       row.out_error_deg,
       double(row.comp_reasons),
       row.readout_damping_sigmas};
}

using Metadata = std::vector<std::pair<std::string, std::string>>;

std::vector<std::pair<std::string, std::string>> telemetry_metadata(const RunConfig& job) {
  return {{"source", "hrg sim (firmware + sim_target in lockstep)"},
          {"scenario", job.description},
          {"quad_v", "a_B, the quadrature wave amplitude"}};
}

// The run's header: the above and the firmware's own estimates.
Metadata telemetry_metadata(const RunConfig& job, const RunResult& r) {
  // The firmware's own estimates, for hrg audit --calibration
  // (tools/audit/README.md): absent when not measured.
  Metadata meta = telemetry_metadata(job);
  for (auto& kv : hrg::can::estimates_header(r.firmware_estimates))
    meta.push_back(std::move(kv));
  return meta;
}

}  // namespace

std::vector<std::filesystem::path> write_telemetry(const std::filesystem::path& path,
                                                   const RunConfig& job, const RunResult& r,
                                                   const TelemetryFileOptions& o) {
  // Streamed row by row: an hour of telemetry is not held twice in memory.
  std::vector<std::filesystem::path> files;
  auto meta = telemetry_metadata(job, r);
  const std::size_t every = o.decimate > 1 ? o.decimate : 1;
  if (every > 1)
    meta.emplace_back("decimation", fmt("every %zu-th row of %.0f Hz", every, job.telemetry_hz));
  const auto file_for = [&](std::size_t part) {
    if (!(o.rotate_s > 0.0)) return path;
    std::filesystem::path p = path;
    p.replace_filename(path.stem().string() + fmt("-%03zu", part) + path.extension().string());
    return p;
  };
  std::unique_ptr<recording::RecordingWriter> wr;
  std::size_t part = 0;
  std::vector<double> v;
  for (std::size_t i = 0; i < r.rows.size(); i += every) {
    const TelemetryRow& row = r.rows[i];
    const std::size_t part_now =
        o.rotate_s > 0.0 ? static_cast<std::size_t>(std::max(row.t_s, 0.0) / o.rotate_s) : 0;
    if (!wr || part_now != part) {
      if (wr) wr->close();
      part = part_now;
      files.push_back(file_for(part));
      wr = std::make_unique<recording::RecordingWriter>(files.back(), telemetry_columns(),
                                                        job.firmware.chain.f_center_hz,
                                                        job.firmware.gyro.angular_gain, meta);
    }
    telemetry_values(row, v);
    wr->write_row(v);
  }
  if (wr) wr->close();
  return files;
}

recording::Recording telemetry_recording(const RunConfig& job, const RunResult& r) {
  recording::Recording rec(telemetry_columns(), job.firmware.chain.f_center_hz,
                           job.firmware.gyro.angular_gain);
  for (const auto& [key, value] : telemetry_metadata(job, r))
    rec.set_metadata(key, value);
  std::vector<double> v;
  for (const TelemetryRow& row : r.rows) {
    telemetry_values(row, v);
    rec.append_row(v);
  }
  rec.find_gaps();
  return rec;
}

void write_bias_csv(const std::filesystem::path& path, const RunResult& r) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path.string());
  f << "theta_deg,raw_dph,compensated_dph,model_dph\n";
  for (const auto& p : r.parks) {
    f << p.theta_rad * 180.0 / kPi << ',' << p.bias_raw_dph << ',' << p.bias_comp_dph << ','
      << p.bias_model_dph << '\n';
  }
}

void write_allan_csv(const std::filesystem::path& path, const RunResult& r) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path.string());
  f << "tau_s,adev_dph\n";
  for (const auto& p : r.allan)
    f << p.tau_s << ',' << p.adev * kRadSToDph << '\n';
}

std::string describe_share(const RunResult& r) {
  const std::string wall = fmt("%.1f %% by wall time", 100.0 * r.sim_share);
  if (r.sim_share_cpu < 0) return "n/a by CPU time (no unpreempted stretch); " + wall;
  return fmt("%.1f %% by CPU time (%.0f %% of the stretches unpreempted); ",
             100.0 * r.sim_share_cpu, 100.0 * r.share_stretches_kept) +
         wall;
}

void print_summary(std::FILE* out, const RunConfig& job, const RunResult& r) {
  TextTable run("run");
  run.row({"simulated", fmt("%.1f s", r.sim_s)});
  run.row({"wall", fmt("%.1f s", r.wall_s)});
  run.row({"realtime factor", fmt("%.1f x wall, %.1f x CPU (fs %u Hz, one core)", r.realtime_factor,
                                  r.realtime_factor_cpu, job.sim.adc.sample_rate_hz)});
  run.row({"simulated target", describe_share(r)});
  run.row({"operate from", fmt("%.2f s", r.t_operate_s)});
  run.row({"final mode", fw::to_string(r.final_mode)});
  run.row(
      {"excitation off", fmt("%.2f %% (%u windows, %u accepted)", 100.0 * r.excitation_off_fraction,
                             r.windows, r.windows_accepted)});
  run.row({"tracking rms", fmt("%.4f deg (max %.4f)", r.tracking_rms_deg, r.tracking_max_deg)});
  run.row({"error at end", fmt("raw %.4f deg, model %.4f deg, compensated %.4f deg",
                               r.raw_error_end_deg, r.model_error_end_deg, r.comp_error_end_deg)});
  double adev_min = 0, tau_min = 0;
  for (const auto& p : r.allan) {
    if (adev_min == 0 || p.adev < adev_min) {
      adev_min = p.adev;
      tau_min = p.tau_s;
    }
  }
  run.row({"Allan deviation", fmt("min %.3f deg/h at %.1f s (over a %.0f s still record)",
                                  adev_min * kRadSToDph, tau_min, r.allan_span_s)});
  run.print(out);

  TextTable id(fmt("identification (estimate +- sigma, Cramer-Rao bound at %.2g V, truth)",
                   r.noise_sigma_v));
  for (int i = 0; i < 5; ++i) {
    id.row({kParamNames[i], fmt("%+.4e", r.identification.p[i]),
            fmt("+- %.1e", r.identification.sigma[i]),
            fmt("CRB %.1e", r.crb_sigma[static_cast<std::size_t>(i)]),
            fmt("%+.4e", r.truth[static_cast<std::size_t>(i)])});
  }
  id.row({"condition", fmt("%.1f", r.condition), fmt("coverage %.2f", r.coverage),
          r.identification.valid ? "accepted" : "not accepted",
          r.t_converged_s >= 0 ? fmt("converged at %.1f s", r.t_converged_s)
                               : std::string("campaign not done")});
  id.print(out);

  TextTable bias("angle-dependent bias, b + A sin4th + B cos4th (deg/h, input axis)");
  bias.row({"", "mean b", "ADB sqrt(A^2+B^2)", "A", "B"});
  const auto add = [&](const char* name, const BiasFit& f) {
    if (f.degenerate()) {
      bias.row({name, fmt("%+.3f (parks)", f.park_mean), "not separable", "-", "-"});
      return;
    }
    bias.row({name, fmt("%+.3f", f.b0), fmt("%.3f", f.amplitude()), fmt("%+.3f", f.a_sin4),
              fmt("%+.3f", f.b_cos4)});
  };
  add("raw", r.fit_raw);
  add("compensated", r.fit_comp);
  add("drift model (truth)", r.fit_model);
  bias.row({"parked angles", fmt("%zu (compensated fit over the %zu with the model valid)",
                                 r.parks.size(), r.parks_model_valid)});
  bias.row({"control-loop drift", fmt("%+.3f", r.control_drift_mean_dph), "(mean D_Phi/K added)",
            fmt("%+.3f withheld", r.control_drift_withheld_mean_dph)});
  bias.row({"compensation", r.compensation_valid ? "valid" : "not valid",
            "why not: " + compensation_reason_text(r.compensation_reasons),
            fmt("readout check %.1f sigma", r.readout_damping_sigmas)});
  bias.print(out);
  if (r.fit_comp.degenerate())
    std::fprintf(out, "  bias test: %s\n", degenerate_parks_note(r.fit_comp).c_str());
  if (r.parks_model_valid < r.parks.size())
    std::fprintf(out, "  bias test: %s\n", bias_test_coverage(r).c_str());

  TextTable ex(r.real_time ? "executive (real time: " + r.realtime_setup + ")"
                           : std::string("executive (lockstep; host time per task)"));
  ex.row({"task", "rate", "budget", "max", "mean", "overruns", "slips"});
  for (const auto& t : r.tasks) {
    ex.row({t.name, fmt("%u Hz", t.rate_hz), fmt("%.0f us", t.budget_ns / 1e3),
            fmt("%.1f us", t.max_ns / 1e3), fmt("%.2f us", t.mean_ns / 1e3), fmt("%u", t.overruns),
            fmt("%u", t.slips)});
  }
  ex.print(out);
  std::fprintf(out, "  frames %llu, missed %u, deadline misses %u, max frame %.1f us\n",
               static_cast<unsigned long long>(r.frames.frames), r.frames.missed_frames,
               r.frames.deadline_misses, r.frames.max_frame_ns / 1e3);
  if (r.failures.empty()) {
    std::fprintf(out, "result: PASS\n");
  } else {
    for (const auto& f : r.failures)
      std::fprintf(out, "FAIL: %s\n", f.c_str());
  }
}

}  // namespace hrg::sim_run
