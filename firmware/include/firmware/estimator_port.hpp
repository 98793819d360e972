// SPDX-License-Identifier: MIT
#pragma once

#include "estimator/damping_model_check.hpp"
#include "estimator/estimator.hpp"
#include "estimator/pickoff_self_calibration.hpp"
#include "firmware/calibration.hpp"
#include "firmware/chain_and_identifier.hpp"

namespace hrg::fw {

// The firmware's ResonatorIdentifier over est::Estimator (seed section 5): window
// samples go to the accumulator, solve() folds nothing new but re-solves and
// accepts the model when the conditioning allows, the drift is eq. 22.
class EstimatorPort final : public ResonatorIdentifier {
 public:
  explicit EstimatorPort(const est::Estimator::Config& cfg) : cfg_(cfg), est_(cfg), seed_est_(cfg) {
    refresh_readout_figures();
  }

  void begin_window(double t_s) override;
  void add_sample(const ChainRecord& s) override;
  void end_window() override;
  void end_check_window() override;
  void abort_window() override;
  void solve() override;
  // Read every output frame: the readout figures in health_ are refreshed
  // where what they are computed from changes (refresh_readout_figures).
  EstimatorHealth health() const override {
    EstimatorHealth h = health_;
    h.control_drift_lost = est_.pump_drift_lost();
    h.pump_drift_in_use = est_.pump_drift().usable() || est_.known_gap_in_use();
    return h;
  }
  Identification identification() const override;
  double drift_rad_s(double theta_a_rad, double ab_over_aa, double e_v2) const override {
    return est_.drift_rate_rad_s(theta_a_rad, ab_over_aa, damping_scale(e_v2));
  }
  void set_temperature_c(double temp_c, bool valid) override {
    temp_c_ = temp_c;
    temp_valid_ = valid;
  }
  // The calibration's resonator model (thermal damping with its reference
  // temperature, nonlinear damping) that the windows' regressors and the
  // drift are referred to: the identified damping is the reference
  // state's, so a known change of the common damping with temperature or
  // amplitude is not taken for anisotropy. Call between windows. A new
  // damping part starts its check (damping_model_check) again.
  void set_resonator_model(const Calibration& cal);
  // The known factor on the whole damping now, at energy e_v2 (V^2) and the
  // measured temperature (the reference temperature without a sensor).
  double damping_scale(double e_v2) const {
    return fw::damping_scale(model_, temp_valid_ ? temp_c_ : model_.temperature_ref_c, e_v2);
  }
  void add_control_sample(const ChainRecord& s) override;
  double control_drift_rad_s(const ChainRecord& s) override;

  const est::Estimator& estimator() const { return est_; }
  // The pickoff self-calibration over the same windows (campaign and check
  // windows alike): its last solve (re-solved after every window).
  const est::PickoffSelfCalResult& pickoff_self_calibration() const { return self_cal_result_; }
  // Do no harm for the resonator model: whether its damping terms fit the
  // windows (campaign and check windows alike) better than none
  // (est::DampingModelCheck), re-solved after every window.
  const est::DampingModelCheckResult& damping_model_check() const { return model_check_result_; }
  // Without a damping part in force the check tries one: a thermal damping
  // of kThermalProbePerC about the calibration's reference temperature (no
  // part of the model, nothing applied), so that its factor times that is
  // the firmware's own reading of the coefficient; the guard judges the
  // check only with a damping part in force.
  static constexpr double kThermalProbePerC = 0.01;
  // The thermal damping coefficient the check reads (1/degC, 1 sigma): f
  // times the probe's or the calibration's beta; not valid before the check
  // solves, or with a nonlinear damping in force (f scales both terms).
  struct ThermalDampingReading {
    bool valid = false;
    double per_c = 0.0;
    double sigma_per_c = 0.0;
  };
  ThermalDampingReading thermal_damping_reading() const;
  // The model and D_Phi forget every window (the signals or the model they
  // are referred to changed); the self-calibration keeps its windows.
  void restart_model();
  // The damping model check refuted the resonator model's damping part: the
  // seed's model identified beside it from the same windows (k = 1) takes
  // over, nothing is lost (the caller then sets the model without its
  // damping part). Until the check has judged the part (refuted or
  // supported) every window and control sample goes to both.
  void fall_back_to_seed_model();
  // The check supports the damping part: the seed's model is no longer kept.
  void keep_resonator_model() { shadow_ = false; }
  bool seed_model_kept() const { return shadow_; }
  // A new pickoff correction (`applied`, a self-calibration result, on top of
  // the one in force) changed the signals: the model and D_Phi forget every
  // window; the self-calibration keeps them, re-referred through it
  // (est::PickoffSelfCalibration::refer_to_applied).
  void restart_after_correction(const est::PickoffSelfCalResult& applied);
  // The pickoff correction changed by `step` while the model keeps its
  // windows (a calibration withdrawn): the self-calibration's windows are
  // re-referred through it, so its residual stays one of the map in force.
  void refer_self_calibration(const est::PickoffSelfCalResult& step);
  // The gap harmonic a calibration gives (both zero: not known, fitted
  // online), with its own sigmas (0: not given). Kept across restart();
  // changes no window.
  void set_known_gap(const est::Estimator::Config::KnownGap& gap) {
    cfg_.gap = gap;
    est_.set_known_gap(cfg_.gap);
    seed_est_.set_known_gap(cfg_.gap);
  }
  uint32_t windows_accepted() const { return windows_ok_; }
  uint32_t windows_rejected() const { return windows_bad_; }
  uint32_t solves_accepted() const { return solves_ok_; }

 private:
  // EstimatorHealth::readout_damping_sigmas of the model in force.
  double readout_damping_sigmas() const;
  // The readout checks' figures into health_. They depend on the model in
  // force, its solution, the self-calibration's result and the damping
  // model only, so they are computed where one of those changes (a solve,
  // a restart, a new resonator model, the fall-back), not every frame.
  void refresh_readout_figures();
  // The seed's model (and its shadow) solved again if a window came in.
  void solve_model();
  void end_side_windows();
  // The damping scale of the thermal probe at the measured temperature.
  double probe_scale() const;
  void add_control_sample(est::Estimator& e, const ChainRecord& s, double scale, bool gap);

  est::Estimator::Config cfg_;
  est::Estimator est_;
  // The seed's model (k = 1) from the same windows while a damping part is
  // on trial (shadow_).
  est::Estimator seed_est_;
  bool shadow_ = false;
  Calibration model_{};  // its resonator part is used here
  double temp_c_ = 0.0;
  bool temp_valid_ = false;
  est::PickoffSelfCalibration self_cal_;
  est::PickoffSelfCalResult self_cal_result_{};
  est::DampingModelCheck model_check_;
  est::DampingModelCheckResult model_check_result_{};
  EstimatorHealth health_{};
  bool dirty_ = false;           // a window was added since the last solve
  bool self_cal_dirty_ = false;  // a window was added to the self-calibration
  bool check_dirty_ = false;     // a window was added to the damping model check
  // Control samples further apart than this (s) restart the D_Phi blocks.
  static constexpr double kMaxControlGapS = 0.0015;
  double last_control_t_s_ = -1.0;
  uint32_t windows_ok_ = 0;
  uint32_t windows_bad_ = 0;
  uint32_t solves_ok_ = 0;
};

}  // namespace hrg::fw
