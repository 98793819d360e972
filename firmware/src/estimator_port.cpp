// SPDX-License-Identifier: MIT
#include "firmware/estimator_port.hpp"

#include <algorithm>
#include <cmath>

namespace hrg::fw {

namespace {

// The record's values in the estimator's sample types (the estimator does not
// see dsp/, so the chain's record is translated here and nowhere else).
est::WaveSample wave_sample(const ChainRecord& s, double damping_scale) {
  return {.t_s = s.t_s,
          .a_A_v = s.wave.a_A_v,
          .a_B_v = s.wave.a_B_v,
          .theta_A_rad = s.theta_A_rad,
          .E_v2 = s.wave.E_v2,
          .damping_scale = damping_scale};
}

est::ControlDriftEstimator::Sample control_sample(const ChainRecord& s, double damping_scale) {
  return {.t_s = s.t_s,
          .a_A_v = s.wave.a_A_v,
          .a_B_v = s.wave.a_B_v,
          .theta_A_rad = s.theta_A_rad,
          .pump_phase_error_rad = s.pump_phase_error_rad,
          .quad_force_sin_v_s = s.quad_force_sin_v_s,
          .quad_force_cos_v_s = s.quad_force_cos_v_s,
          .pump_v = s.pump_v,
          .damping_scale = damping_scale};
}

}  // namespace

void EstimatorPort::begin_window(double t_s) {
  (void)est_.begin_window(t_s);
  if (shadow_) (void)seed_est_.begin_window(t_s);
  (void)self_cal_.begin_window();
  model_check_.begin_window();
}

void EstimatorPort::end_side_windows() {
  if (self_cal_.end_window() == est::Status::ok) self_cal_dirty_ = true;
  if (model_check_.end_window() == est::Status::ok) check_dirty_ = true;
}

void EstimatorPort::set_resonator_model(const Calibration& cal) {
  const bool same_damping = cal.thermal_damping_per_c == model_.thermal_damping_per_c &&
                            cal.temperature_ref_c == model_.temperature_ref_c &&
                            cal.nonlinear_damping_per_v2 == model_.nonlinear_damping_per_v2;
  model_ = cal;
  refresh_readout_figures();  // the damping check's rule reads model_
  if (same_damping) return;
  model_check_.reset();
  model_check_result_ = {};
  check_dirty_ = false;
  // Until the check has judged a damping part, the seed's model is
  // identified beside it from the same windows (from what is known now).
  shadow_ = has_damping_model(cal);
  if (shadow_) seed_est_ = est_;
}

void EstimatorPort::fall_back_to_seed_model() {
  if (!shadow_) return;
  shadow_ = false;
  est_ = seed_est_;
  dirty_ = true;  // solved again at the next solve()
  health_.window_misfit = est_.last_window_misfit();
  health_.windows_checked = est_.windows_checked();
  refresh_readout_figures();
}

void EstimatorPort::restart_model() {
  est_ = est::Estimator(cfg_);
  if (shadow_) seed_est_ = est_;
  health_ = {};
  dirty_ = false;
  last_control_t_s_ = -1.0;
  refresh_readout_figures();
}

void EstimatorPort::restart_after_correction(const est::PickoffSelfCalResult& applied) {
  restart_model();
  refer_self_calibration(applied);
  // The windows' levels changed with the correction, their decay did not:
  // the damping model check keeps them.
}

void EstimatorPort::refer_self_calibration(const est::PickoffSelfCalResult& step) {
  self_cal_.refer_to_applied(step);
  self_cal_result_ = {};
  self_cal_dirty_ = true;  // the re-referred residual, solved at the next solve()
  refresh_readout_figures();
}

void EstimatorPort::add_sample(const ChainRecord& s) {
  // Settling samples and sequencing errors are the accumulator's to count;
  // the self-calibration takes the samples the accumulator took.
  const est::WaveSample w = wave_sample(s, damping_scale(s.wave.E_v2));
  if (shadow_) (void)seed_est_.add_sample(wave_sample(s, 1.0));
  if (est_.add_sample(w) == est::Status::ok) {
    (void)self_cal_.add_sample(w);
    (void)model_check_.add_sample(has_damping_model(model_) ? w : wave_sample(s, probe_scale()));
  }
}

double EstimatorPort::probe_scale() const {
  // No sensor: k = 1, nothing for the check to see.
  return temp_valid_ ? 1.0 + kThermalProbePerC * (temp_c_ - model_.temperature_ref_c) : 1.0;
}

EstimatorPort::ThermalDampingReading EstimatorPort::thermal_damping_reading() const {
  const est::DampingModelCheckResult& d = model_check_result_;
  if (d.status != est::Status::ok || model_.nonlinear_damping_per_v2 != 0.0) return {};
  const double beta = has_damping_model(model_) ? model_.thermal_damping_per_c : kThermalProbePerC;
  return {true, d.factor * beta, d.factor_sigma * std::fabs(beta)};
}

void EstimatorPort::end_window() {
  end_side_windows();
  if (shadow_) (void)seed_est_.end_window();
  if (est_.end_window() == est::Status::ok) {
    ++windows_ok_;
    dirty_ = true;
    health_.window_misfit = est_.last_window_misfit();
    health_.windows_checked = est_.windows_checked();
  } else {
    ++windows_bad_;
  }
}

void EstimatorPort::end_check_window() {
  end_side_windows();
  if (shadow_) (void)seed_est_.end_window(false);
  if (est_.end_window(false) == est::Status::ok) {
    ++windows_ok_;  // accepted as a check (nothing new to solve)
    health_.window_misfit = est_.last_window_misfit();
    health_.windows_checked = est_.windows_checked();
  } else {
    ++windows_bad_;
  }
}

void EstimatorPort::abort_window() {
  // A window cut short by a fault is dropped: its last samples may already
  // show the fault, and a short window is worth little anyway.
  self_cal_.abort_window();
  model_check_.abort_window();
  if (shadow_ && seed_est_.window().window_open()) seed_est_.abort_window();
  if (!est_.window().window_open()) return;
  est_.abort_window();
  ++windows_bad_;
}

void EstimatorPort::add_control_sample(const ChainRecord& s) {
  // Samples are taken every control period in operate; a gap (a window, a
  // commanded pattern move) ends the derivative blocks first.
  const bool gap = s.t_s - last_control_t_s_ > kMaxControlGapS;
  last_control_t_s_ = s.t_s;
  add_control_sample(est_, s, damping_scale(s.wave.E_v2), gap);
  if (shadow_) add_control_sample(seed_est_, s, 1.0, gap);
}

void EstimatorPort::add_control_sample(est::Estimator& e, const ChainRecord& s, double scale,
                                       bool gap) {
  // The D_Phi fits take the identified decay and split as known: before a
  // model is accepted they would fold in a wrong one.
  if (!e.has_model()) return;
  if (gap) e.restart_control();
  // A bad sample restarts the estimate (the estimator's rule).
  (void)e.add_control_sample(control_sample(s, scale));
}

double EstimatorPort::control_drift_rad_s(const ChainRecord& s) {
  return est_.has_model() ? est_.d_phi_rad_s(control_sample(s, damping_scale(s.wave.E_v2))) : 0.0;
}

void EstimatorPort::solve() {
  if (self_cal_dirty_) {
    self_cal_dirty_ = false;
    self_cal_result_ = self_cal_.solve();
  }
  if (check_dirty_) {
    check_dirty_ = false;
    model_check_result_ = model_check_.solve();
  }
  solve_model();
  refresh_readout_figures();
}

void EstimatorPort::solve_model() {
  if (!dirty_) return;
  dirty_ = false;
  if (shadow_) (void)seed_est_.solve_and_accept();
  const est::Solution s = est_.solve_and_accept();
  if (s.accepted()) ++solves_ok_;
  health_.solved = est_.has_model();
  health_.condition = s.cond.kappa_2;
  const auto& cov = est_.coverage_s();
  int covered = 0;
  for (double c : cov)
    covered += c > 0.0 ? 1 : 0;
  health_.coverage = static_cast<double>(covered) / static_cast<double>(cov.size());
}

void EstimatorPort::refresh_readout_figures() {
  health_.readout_damping_sigmas = readout_damping_sigmas();
  health_.readout_pattern_sigmas = est::readout_pattern_sigmas(self_cal_result_);
  health_.readout_phase_sigmas = est::readout_phase_sigmas(self_cal_result_);
  health_.readout_phase_drift_share =
      est_.has_model() ? est::readout_phase_drift_share(self_cal_result_, est_.model()) : 0.0;
}

double EstimatorPort::readout_damping_sigmas() const {
  if (!est_.has_model()) return 0.0;
  // With a damping model in force the windows' damping changes by it (the
  // decay test refuses one nu by design) and the model's damping is the
  // reference state's, the self-identification's the windows' own: its
  // fit with a decay rate per window is not the model's to compare with
  // (nonlinear damping 0.05 /V^2 in force, 1800 s: 15 sigmas apart, the
  // model right).
  if (!self_cal_result_.decay_consistent && has_damping_model(model_)) return 0.0;
  const est::ParamMatrix& c = est_.last_solution().covariance;
  return est::damping_anisotropy_disagreement_sigmas(
      self_cal_result_, est_.model(), std::sqrt(std::max(c(est::kDnuC, est::kDnuC), 0.0)),
      std::sqrt(std::max(c(est::kDnuS, est::kDnuS), 0.0)));
}

Identification EstimatorPort::identification() const {
  Identification id;
  id.valid = est_.has_model();
  const est::Solution& s = est_.last_solution();
  for (int i = 0; i < est::kParams; ++i) {
    id.p[i] = id.valid ? est_.model()(i) : s.p(i);
    const double var = s.covariance(i, i);
    id.sigma[i] = var > 0.0 ? std::sqrt(var) : 0.0;
  }
  return id;
}

}  // namespace hrg::fw
