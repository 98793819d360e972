// SPDX-License-Identifier: MIT
#pragma once

// The estimator as the firmware's cyclic executive calls it.
//
//   free_decay entered:     begin_window(t_switch_s)
//   each 1 kHz tick in it:  add_sample({t_s, a_A, a_B, theta_A, E})
//   free_decay left:        end_window()           -> window folded into the LS
//   free_decay aborted:     abort_window()         -> window dropped
//   at a slow rate (e.g. after each window):  solve_and_accept()
//   each 1 kHz tick:        drift_rate_rad_s(theta_A, a_B/a_A) (+ d_phi_rad_s(theta_A)
//                           with the excitation on) is the drift D whose
//                           integral / K the output adds to -2 (theta_A - theta_A0) / K
//                           (the firmware's AngleOutput, by DriftCompensator::integrate)
//   with excitation on:     add_control_sample(...) feeds the D_Phi estimates
//                           (pump phase error eps = pi/2 - 2 (phi_V - phi_A), pump
//                           amplitude V0, quadrature forcer parts)
//   window scheduler:       conditioning(), coverage_s(), least_covered_theta_rad()
//
// Units: seconds, radians, amplitudes in any consistent unit (volts), rates
// in rad/s. drift_rate_rad_s is D of eq. 7 ("Omega K" units); divide by K for
// input rate. No heap, no exceptions; every call is bounded (see the bench).

#include <estimator/drift.hpp>
#include <estimator/normal_equations.hpp>
#include <estimator/window_accumulator.hpp>

namespace hrg::est {

class Estimator {
 public:
  // Forgetting derived from how fast the parameters are seen to move (used
  // when NormalEquations::Config::forgetting_time_s is 0, i.e. not set).
  // Each accepted solve is compared with an anchor solution; a parameter
  // that moved more than `move_sigmas` standard errors of the difference
  // (nested fits: C_anchor - C_now) sets the memory that balances the lag
  // of a drift at the seen rate r against the noise, tau = (s^2 / 2r^2)^(1/3)
  // with s^2 the variance of the parameter times the data's span, and the
  // anchor moves on. Nothing seen: no forgetting (the model keeps
  // converging as 1/sqrt(T)); a memory in force lengthens to the span over
  // which nothing moved.
  // Off by default: measured on a +-2 degC thermal-damping swing (3 h, the
  // pattern parked between check windows), a derived memory of 3000 s left a
  // model ADB of 3.07 deg/h against 1.12 without forgetting; the windows at
  // one parked angle cannot hold the anisotropy apart from the common
  // damping's thermal change.
  struct Forgetting {
    bool adaptive = false;
    double move_sigmas = 4.5;  // 5 parameters, ~350 solves a day: ~1 % false alarm
    double min_s = 3000.0;     // memory floor (the windows must cover the 4 theta bins in it)
    double min_windows = 16;   // the anchor is taken once the fit holds this many windows
  };

  struct Config {
    Variant variant = Variant::joint;
    WindowAccumulator::Config window{};
    NormalEquations::Config ls{};
    ControlDriftEstimator::Config control{};
    PumpDriftEstimator::Config pump{};
    Forgetting forgetting{};
    // The ring electrode's gap harmonic when a calibration gives it
    // (eps_p, eps_q of docs/effects-catalog.md): the pump's part of D_Phi is
    // then known_gap_drift_rad_s with the accepted model, from the first
    // model on, until the online fit is usable (it needs its own
    // significance, minutes of excitation). Both zero: not known, the online
    // fit alone. The sigmas are the calibration's own one-standard-deviation
    // uncertainties (an audit's fit of a few minutes); 0: not given, the gap
    // is checked as if exact.
    struct KnownGap {
      double eps_p = 0.0;
      double eps_q = 0.0;
      double sigma_eps_p = 0.0;
      double sigma_eps_q = 0.0;
      bool known() const { return eps_p != 0.0 || eps_q != 0.0; }
    };
    KnownGap gap{};
  };

  explicit Estimator(const Config& c)
      : config_(c), window_(c.window), ls_(c.ls), control_(c.control), pump_(c.pump) {}

  Status begin_window(double t_switch_s) {
    // The excitation-on segment of the pump fit ends here.
    pump_.restart();
    return window_.begin_window(t_switch_s);
  }
  Status add_sample(const WaveSample& s) { return window_.add_sample(s); }
  // Drops the open window without folding it (a fault during the free decay).
  void abort_window() {
    window_.abort_window();
    control_.restart();
  }
  // Folds the window into the normal equations; Status::too_short etc. drop it.
  // With `fold` false the window is only checked against the model in force
  // (a check window: the model it tests stays what it was).
  Status end_window(bool fold = true);
  // Solves the configured variant; the model used for compensation changes
  // only if the solution is accepted (conditioning below the threshold).
  Solution solve_and_accept();

  // D_nu + D_w (eqs. 6/7/22, drift.hpp) with the accepted model, rad/s ("Omega K" units),
  // its damping referred to the present state by damping_scale (WaveSample::damping_scale).
  double drift_rate_rad_s(double theta_A_rad, double aB_over_aA, double damping_scale = 1.0) const {
    if (!has_model_) return 0.0;
    return damping_scale == 1.0 ? resonator_drift_rad_s(model_, theta_A_rad, aB_over_aA)
                                : resonator_drift_rad_s(with_damping_scale(model_, damping_scale),
                                                        theta_A_rad, aB_over_aA);
  }
  // Feeds both D_Phi estimators (eq. 23 and the pump's gap part); false if
  // either refused the sample (it then restarts).
  bool add_control_sample(const ControlDriftEstimator::Sample& s) {
    const bool control_ok = control_.add_sample(s);
    const bool pump_ok = pump_.add_sample(s);
    if (pump_.usable()) pump_used_ = true;
    check_known_gap();
    return control_ok && pump_ok;
  }
  // Ends the D_Phi derivative blocks when the control samples stop for a
  // while (e.g. a commanded pattern move) without touching the window.
  void restart_control() {
    control_.restart();
    pump_.restart();
  }

  bool has_model() const { return has_model_; }
  // The model check on each window folded while a model is in force: the
  // window's own residual sum of squares against the accepted model, per
  // degree of freedom, over the accepted fit's residual variance (1 when
  // the model holds for this window as for the windows it was fitted on;
  // a window at another turn rate or temperature shows what the fit absorbed).
  // 0 until a window has been checked.
  double last_window_misfit() const { return last_misfit_; }
  uint32_t windows_checked() const { return windows_checked_; }
  const ParamVector& model() const { return model_; }
  const Solution& last_solution() const { return last_; }
  // D_Phi at pattern angle theta (eq. 23 part + ring-pump gap part), rad/s;
  // each part only when it clears its own uncertainty (nothing is added
  // when there is nothing to find).
  double d_phi_rad_s(double theta_A_rad) const {
    return control_.used_d_phi_rad_s() + pump_d_phi_rad_s(theta_A_rad);
  }
  // D_Phi for the output at one sample with the excitation on (one call
  // per output sample: the known gap's part follows the wave's amplitude
  // from call to call, KnownGapDrift); otherwise as d_phi_rad_s(theta).
  double d_phi_rad_s(const ControlDriftEstimator::Sample& s) {
    if (!known_gap_in_use()) return d_phi_rad_s(s.theta_A_rad);
    const double a = s.a_A_v > 0.0 ? s.a_B_v / s.a_A_v : 0.0;
    return control_.used_d_phi_rad_s() + known_gap_.step(model_, config_.gap.eps_p,
                                                         config_.gap.eps_q, s.t_s, s.theta_A_rad,
                                                         s.a_A_v, a, s.damping_scale);
  }
  // The ring pump's part of D_Phi: from the online fit once it is usable
  // (it measures this gyro now, over every excitation-on row; a calibration's
  // gap was measured once, by a fit of a few minutes, and is its prior until
  // then); before that from the known gap (Config::gap) with the accepted
  // model at the AGC's balance.
  double pump_d_phi_rad_s(double theta_A_rad) const {
    if (pump_.usable()) return pump_.d_phi_rad_s(theta_A_rad);
    if (config_.gap.known() && !gap_refuted_ && has_model_)
      return known_gap_drift_rad_s(model_, config_.gap.eps_p, config_.gap.eps_q, theta_A_rad);
    return 0.0;
  }
  // The known gap gives the pump's part of D_Phi now: in the calibration,
  // not refuted, a model to scale it, and no usable online fit yet.
  bool known_gap_in_use() const {
    return config_.gap.known() && !gap_refuted_ && has_model_ && !pump_.usable();
  }
  // A calibration's gap harmonic (both zero: not known). Keeps everything fitted.
  // A new gap is on trial again (check_known_gap).
  void set_known_gap(const Config::KnownGap& g) {
    config_.gap = g;
    gap_refuted_ = false;
    gap_checked_fit_s_ = -1.0;
  }
  const Config::KnownGap& known_gap() const { return config_.gap; }
  // The known gap disagreed with the online fit (do no harm): the pump's
  // D_Phi is the online fit's again (when usable), for the rest of the run.
  bool known_gap_refuted() const { return gap_refuted_; }
  // Do no harm: the online pump fit's D_Phi was added to the output and no
  // longer is (its fit withdrawn or its gap no longer significant) while no
  // known gap stands in for it. The output then misses a drift the firmware
  // has measured (up to nu |eps| / 2: 64 deg/h at Q 1e6 with a gap harmonic
  // of 0.03); the firmware does not call such a compensation valid.
  bool pump_drift_lost() const {
    return pump_used_ && !pump_.usable() && !(config_.gap.known() && !gap_refuted_);
  }
  const PumpDriftEstimator& pump_drift() const { return pump_; }
  const ControlDriftEstimator& control_drift() const { return control_; }
  Conditioning conditioning() const { return ls_.conditioning(); }
  const CoverageHistogram& coverage_s() const { return ls_.coverage_s(); }
  // Pattern angle (centre of the least covered 4theta bin, in [0, pi/2)).
  double least_covered_theta_rad() const;
  ParamMatrix cramer_rao_bound(double sigma_v) const { return ls_.cramer_rao_bound(sigma_v); }
  const NormalEquations& normal_equations() const { return ls_; }
  // Memory of the normal equations now (s, 0: none), configured or derived.
  double forgetting_time_s() const { return ls_.config().forgetting_time_s; }
  const WindowAccumulator& window() const { return window_; }

 private:
  Config config_;
  WindowAccumulator window_;
  NormalEquations ls_;
  ParamVector model_ = ParamVector::Zero();  // the accepted model
  bool has_model_ = false;
  ControlDriftEstimator control_;
  PumpDriftEstimator pump_;
  KnownGapDrift known_gap_;
  void check_window(const WindowContribution& w);
  // The known gap against the online fit, once per folded segment: refuted
  // when the fit stands PumpDriftEstimator::Config::min_gap_sigmas away from
  // it, in the uncertainty of the difference: the fit's and the gap's own
  // (KnownGap's sigmas) together, two independent measurements (a wrong sign
  // stands out twice as fast as the gap itself becomes usable online).
  void check_known_gap();
  bool gap_refuted_ = false;
  double gap_checked_fit_s_ = -1.0;
  bool pump_used_ = false;  // the online pump fit's D_Phi has been usable
  void update_forgetting(const Solution& s);
  Solution anchor_{};
  double t_anchor_s_ = 0.0;
  bool have_anchor_ = false;
  double t_first_window_s_ = -1.0;
  double t_last_window_s_ = 0.0;
  WindowContribution scratch_{};
  Solution last_{};
  double last_misfit_ = 0.0;
  uint32_t windows_checked_ = 0;
};

}  // namespace hrg::est
