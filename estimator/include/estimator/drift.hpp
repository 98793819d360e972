// SPDX-License-Identifier: MIT
#pragma once

// Drift of the pattern angle and its compensation (docs/physics.md section 3,
// the paper's eqs. 6, 7, 14, 22, 23, 29).
//
//   Omega K = -2 theta_A' + D,   D = D_nu + D_w + D_Phi   (all rad/s, "Omega K" units)
//
// Resonator part, eq. 6 divided by a_A^2 - a_B^2 (q = a_B/a_A):
//   D_nu + D_w = [nu dmu sin4(th - th_mu) (1 + q^2) - 2 q dw cos4(th - th_w)] / (1 - q^2)
//   nu dmu sin4(th - th_mu) = dnu_C sin4th - dnu_S cos4th
//   dw cos4(th - th_w)      = dw_C cos4th + dw_S sin4th          (eq. 14)
// To first order in q this is eq. 7. The paper's eq. 22 writes the split part
// as -2q (dw_C sin4th + dw_S cos4th), which disagrees with its own eqs. 7 and
// 14; the averaged model (sim_target) agrees with eq. 14 and with the exact
// factors above to 1e-5 (tests/estimator/test_monte_carlo.cpp measures it).
//
// Control-loop part, eq. 23:
//   D_Phi = -(a_PhiB/a_A) cos dphi_B + q (a_PhiA/a_A) cos dphi_A
//
// The gyro's input angle is -2 (theta_A - theta_A0)/K + integral of D/K dt; the
// compensator integrates the modelled D/K, so a new estimate changes only the
// rate from then on and the output never jumps.

#include <array>
#include <cstdint>
#include <limits>

#include <estimator/types.hpp>

namespace hrg::est {

// D_nu + D_w (eq. 6 form above) for parameters p at pattern angle theta_A_rad with the
// measured a_B/a_A. rad/s in Omega K units. Any context.
double resonator_drift_rad_s(const ParamVector& p, double theta_A_rad, double aB_over_aA);

// p with its damping part (nu, dnu_C, dnu_S) multiplied by damping_scale:
// a model identified at the reference state (WaveSample::damping_scale)
// referred to the present temperature and amplitude. The split is kept.
ParamVector with_damping_scale(const ParamVector& p, double damping_scale);

// D_Phi of the ring-electrode pump for a known gap harmonic (eps_p, eps_q),
// the same physics as PumpDriftEstimator below with the gap given (a
// calibration) instead of fitted. The pump's in-phase growth rate kappa is
// what eq. 3 leaves on a_A (the left side of eq. 20 over a_A):
//   kappa (1 + eps_p/2 cos4th + eps_q/2 sin4th)
//     = a_A'/a_A + k (nu + dnu_C cos4th + dnu_S sin4th) + (dw_C sin4th - dw_S cos4th) a_B/a_A
// (k the damping scale, WaveSample::damping_scale), and then
//   D_Phi = kappa (eps_q/2 cos4th - eps_p/2 sin4th).
// growth_per_s is a_A'/a_A: 0 where the AGC holds the amplitude, but the
// pump also makes up what each free-decay window lost (nu T_off, ~12 % of
// the pump's work with the default windows), so the output path gives the
// measured one (KnownGapDrift). Needs no pump gain and no fit of its own:
// right from the first model. rad/s in Omega K units. Any context.
double known_gap_drift_rad_s(const ParamVector& p, double eps_p, double eps_q, double theta_A_rad,
                             double growth_per_s = 0.0, double aB_over_aA = 0.0,
                             double damping_scale = 1.0);

// known_gap_drift_rad_s with the wave's measured growth a_A'/a_A, for the
// output: one call per output sample while the excitation is on. The growth
// is the difference of ln a_A from the previous call over the time between,
// so its integral over an excitation-on stretch is exactly the change of
// ln a_A there (the amplitude noise does not add up); a gap of more than
// max_sample_gap_s (a free-decay window: no pump) starts afresh at growth 0.
// Context: control-rate task; no heap.
class KnownGapDrift {
 public:
  explicit KnownGapDrift(double max_sample_gap_s = 0.0015) : max_gap_s_(max_sample_gap_s) {}
  // D_Phi (rad/s, Omega K units) at time t_s for the model p and gap
  // (eps_p, eps_q); a non-finite or non-positive a_A gives 0 and restarts.
  double step(const ParamVector& p, double eps_p, double eps_q, double t_s, double theta_A_rad,
              double a_A_v, double aB_over_aA, double damping_scale);
  void restart() { started_ = false; }
  // The last growth a_A'/a_A used (1/s).
  double growth_per_s() const { return growth_per_s_; }

 private:
  double max_gap_s_;
  bool started_{false};
  double t_last_s_{0};
  double ln_a_last_{0};
  double growth_per_s_{0};
};

// Integrates the modelled drift into an angle correction (input-axis radians).
// Context: control-rate task. No heap.
class DriftCompensator {
 public:
  // angular_gain: K (twice the Bryan factor), > 0.
  explicit DriftCompensator(double angular_gain) : k_(angular_gain) {}

  // Model used from the next step on. Before the first call the correction
  // rate is zero.
  void set_model(const ParamVector& p) {
    p_ = p;
    have_model_ = true;
  }
  // Advances by dt_s with the present pattern angle, a_B/a_A and the control
  // loop drift estimate d_phi_rad_s (0 during free decay or if not estimated).
  // Trapezoid rule on the rate; returns the correction to add to the raw angle.
  double step(double theta_A_rad, double aB_over_aA, double d_phi_rad_s, double dt_s);
  // The same rule for a drift D (rad/s, Omega K units) computed elsewhere:
  // the correction advances by the trapezoid of D/K over dt_s.
  double integrate(double d_rad_s, double dt_s);
  // After a gap in the steps (output invalid): the next step starts the
  // trapezoid afresh instead of averaging across the gap.
  void restart_rate() { have_rate_ = false; }
  double correction_rad() const { return correction_rad_; }
  // Last modelled input-rate correction D/K, rad/s.
  double rate_rad_s() const { return rate_rad_s_; }
  bool has_model() const { return have_model_; }
  const ParamVector& model() const { return p_; }
  void reset_angle() { correction_rad_ = 0; }

 private:
  double k_;
  ParamVector p_ = ParamVector::Zero();
  bool have_model_{false};
  bool have_rate_{false};
  double rate_rad_s_{0};
  double correction_rad_{0};
};

// Control-loop drift D_Phi (sections 6-7) with the excitation on. With the
// resonator identified, the left sides of eq. 3 (in the split form of eq. 20)
//   f_A = a_A' + (nu + dnu(th)) a_A + g(th) a_B     = a_PhiA sin dphi_A
//   f_B = a_B' + (nu - dnu(th)) a_B - g(th) a_A     = a_PhiB sin dphi_B
// (dnu(th) = dnu_C cos4th + dnu_S sin4th, g(th) = dw_C sin4th - dw_S cos4th)
// give the in-phase parts of the drives. Their out-of-phase parts follow from
// the measured pump phase error eps = pi/2 - dphi_A (phase of the pump's
// force against the wave's, minus the ideal pi/2): a_Phi cos dphi = f tan eps.
// A quadrature forcer whose force the firmware commands is given separately
// (its in-phase and out-of-phase parts); the rest of f_B is the pump's share,
// which has the pump's phase error. Then eq. 23:
//   D_Phi = -(fB_cos)/a_A + q fA_cos / a_A.
// Derivatives come from block means over `block_s` (differences, never per
// sample), the estimate is low-passed with time constant `smoothing_s`.
class ControlDriftEstimator {
 public:
  struct Config {
    double block_s = 0.1;      // block length for the derivative estimate
    double smoothing_s = 5.0;  // first-order low-pass of D_Phi
    // The estimate is used (used_d_phi_rad_s) only when it stands this many
    // of its own standard errors away from zero: with nothing to find, the
    // noise of the block derivatives would otherwise be added as drift.
    // 0: always used.
    double min_sigmas = 3.0;
  };
  struct Sample {
    double t_s{0};
    double a_A_v{0};
    double a_B_v{0};
    double theta_A_rad{0};
    double pump_phase_error_rad{0};  // eps_A = pi/2 - (phi_PhiA - phi_A)
    double quad_force_sin_v_s{0};    // quadrature forcer, part acting on a_B' (V/s)
    double quad_force_cos_v_s{0};    // quadrature forcer, part acting on the angle (V/s)
    double pump_v{0};                // ring-electrode pump amplitude V0 (V), for PumpDriftEstimator
    double damping_scale{1};         // known factor on the damping now (WaveSample::damping_scale)
  };

  ControlDriftEstimator() = default;
  explicit ControlDriftEstimator(const Config& c) : config_(c) {}

  void set_model(const ParamVector& p) { p_ = p; }
  // Feeds one control-rate sample with the excitation on. Returns false (and
  // restarts) on a time step <= 0 or a non-finite or non-positive a_A.
  bool add_sample(const Sample& s);
  // Restart after a free-decay window (the loops re-acquire).
  void restart();
  double d_phi_rad_s() const { return d_phi_rad_s_; }
  // Standard error of d_phi_rad_s(): the spread of the block estimates
  // about it through the low-pass (independent blocks; successive block
  // derivatives are anti-correlated, so this is on the safe side).
  double d_phi_sigma_rad_s() const;
  // d_phi_rad_s() when it clears Config::min_sigmas, else 0.
  double used_d_phi_rad_s() const;
  bool valid() const { return have_estimate_; }

 private:
  struct Block {
    double t{0}, aA{0}, aB{0}, c4{0}, s4{0}, tan_eps{0}, qs{0}, qc{0}, k{0};
    int n{0};
  };
  Config config_{};
  ParamVector p_ = ParamVector::Zero();
  Block acc_{};
  Block prev_{};
  bool have_prev_{false};
  bool have_estimate_{false};
  double t_block_start_s_{0};
  double t_last_s_{0};
  bool started_{false};
  double d_phi_rad_s_{0};
  double d_var_{0};    // low-passed variance of the block estimates about d_phi_rad_s_
  double alpha_{1.0};  // the low-pass's last weight
};

// Drift of the ring-electrode parametric pump through the gap non-uniformity
// (eqs. 25-27). The pump's force on the wave is k V0^2 G Z* (envelope form),
// G = [[1 + eps_p/2, eps_q/2], [eps_q/2, 1 - eps_p/2]] in instrument axes, so
// with the pump locked at the best phase (error eps):
//   on a_A (in phase):  a_A' += kappa (1 + eps_p/2 cos4th + eps_q/2 sin4th) a_A
//   on the angle:       D_Phi = kappa (eps_q/2 cos4th - eps_p/2 sin4th)
//   kappa = c V0^2 cos(eps),  c the pump gain (1/(s V^2))
// i.e. the gap makes the pump an anisotropic negative damping, with the same
// drift signature as D_nu; the paper's eq. 29 (same phase error on A and B)
// misses it. The in-phase part is measured through the left side of eq. 3
// with the resonator identified, in integral form (no differentiation):
//   ln a_A(t) - ln a_A(t0) + int (nu + dnu(th) + g(th) a_B/a_A) dt
//     = b0 int w dt + b1 int w cos4th dt + b2 int w sin4th dt,   w = V0^2 cos(eps)
// with (b0, b1, b2) = c (1, eps_p/2, eps_q/2), an intercept per segment of
// excitation-on time (segments end at a window or every segment_s), and
// block means of block_samples samples as rows. Then
//   D_Phi(th) = w (b2 cos4th - b1 sin4th).
// The known rate is linear in the model p: the rows keep its five integrals
// (int k, int k cos4th, int k sin4th, int q sin4th, -int q cos4th; k the
// damping scale, q = a_B/a_A) apart, and every fit is made with the model in
// force now. Folding y with the model of its own time instead would keep the
// early models' errors (dnu of a few windows) in the fit for good, and
// anisotropic damping the model has since learnt reads as a gap harmonic:
// an error dnu_err in (dnu_C, dnu_S) shows as (b1, b2) = -dnu_err / w.
// The AGC at its lower limit (pump_v 0: the pump applies no force) is a row
// like any other: cutting the segment there would keep only the stretches
// where the amplitude noise did not push the AGC to zero, which depends on
// the angle through the damping the AGC balances (a false gap harmonic of
// 0.03 at Q 2e7, dQ/Q 0.3, where the AGC sits at zero a third of the time).
// Context: control-rate task; no heap.
class PumpDriftEstimator {
 public:
  struct Config {
    int block_samples = 10;
    double segment_s = 10.0;         // a segment is folded into the fit at this length
    double forgetting_time_s = 0.0;  // 0: keep everything
    // Conditioning of the 3x3 before the gap terms are used. Without
    // forgetting, once reached the fit stays valid (valid()).
    double max_kappa_2 = 1.0e3;
    double min_fit_s = 20.0;  // folded excitation-on time before the fit is used
    double max_sample_gap_s = 0.005;
    // The pump's part of D_Phi is used (Estimator::d_phi_rad_s) only when
    // the fitted gap harmonic gap() is at least this. On an ideal electrode
    // the fit leaves |eps| ~ 3e-4 (the default scenario, 1 h), whose D_Phi
    // (nu |eps| / 2, 0.1-0.3 deg/h) is noise, not drift; a machined gap
    // harmonic of 1e-2 drifts by ~10 deg/h. 0: always used.
    double min_gap = 0.0;
    // ... and only when the gap harmonic (b1, b2) stands this many of its own
    // standard errors from zero (gap_sigmas(), the model's uncertainty
    // included): the resonator model's error reads as a gap of
    // 2 |dnu_err| / (b0 w) until the model has converged. Measured with an
    // ideal electrode (1800 s runs, Q 1e6 ... 2e7, dQ/Q 0.01 ... 0.3): at
    // most 3.4 at the end. 0: not checked.
    double min_gap_sigmas = 6.5;
    // Samples between the pump a sample carries (Sample::pump_v, written for
    // the next block) and the rows whose amplitude it moves: the DAC's lead
    // and the demodulator's centre (fw::app::pump_lag_samples, 3 on the
    // default chain). The fit integrates the pump of lag samples before,
    // the pump that acted when the row's amplitude was measured. Misaligned
    // by 3 ms, the fit read the AGC's recovery after each window (the pump
    // high while the amplitude catches up) as 0.2 % more pump gain than the
    // steady parks: the gap harmonic then moved by ~8 % as the parks added
    // one angle at a time. 0 ... kMaxPumpLag.
    int pump_lag_samples = 0;
  };
  static constexpr int kMaxPumpLag = 7;
  using Sample = ControlDriftEstimator::Sample;

  PumpDriftEstimator() { batch_.fill(MatR::Zero()); }
  explicit PumpDriftEstimator(const Config& c) : config_(c) { batch_.fill(MatR::Zero()); }

  // The model every fit uses from now on (all folded rows included), and its
  // covariance (the identification's): the gap harmonic's uncertainty
  // includes what the model's own error moves the fit by, an error in
  // (dnu_C, dnu_S) reading as a gap of 2 |dnu_err| / (b0 w).
  void set_model(const ParamVector& p, const ParamMatrix& covariance = ParamMatrix::Zero());
  // One control-rate sample with the excitation on (pump_v >= 0; 0 when the
  // AGC is at its lower limit). Bad input ends the segment (folding what it
  // holds, as restart()) and returns false.
  bool add_sample(const Sample& s);
  // Ends the present segment (call when a free-decay window starts); the next
  // segment's first row waits for Config::pump_lag_samples pumps.
  void restart();
  // The fit is used: min_fit_s folded and kappa_2() within max_kappa_2, or
  // (without forgetting) it was once.
  bool valid() const;
  // Excitation-on time folded into the fit (s) and the 2-norm condition
  // number of its 3x3 normal matrix (what valid() compares).
  double fit_s() const { return fit_s_; }
  double kappa_2() const;
  // D_Phi of the pump at pattern angle theta for the pump acting at the last
  // sample's row (Config::pump_lag_samples back), rad/s.
  double d_phi_rad_s(double theta_A_rad) const;
  // (b0, b1, b2) = c (1, eps_p/2, eps_q/2); zero before valid().
  Eigen::Vector3d coefficients() const;
  // The fitted gap harmonic |eps| = 2 |(b1, b2)| / b0; 0 before valid().
  double gap() const;
  // Significance of the gap harmonic: sqrt(b' C^-1 b) for b = (b1, b2) and
  // C their covariance: the scatter of kBatches fits over interleaved
  // segments (batch means: the rows of a segment are running integrals, so
  // their residuals are correlated and the fit's own residual would
  // understate it by ~10x), plus the model's covariance carried through the
  // fit (the scatter cannot see it: every batch shares the model). 0 before
  // valid() or while a batch fit is singular.
  double gap_sigmas() const;
  // The same significance for (b1, b2) - g0: how far the fit stands from a
  // gap harmonic given elsewhere (a calibration's, as b0 (eps_p, eps_q)/2),
  // whose own covariance g0_covariance (same units) adds to the fit's: the
  // two are independent measurements. Zero: g0 taken as exact.
  double gap_sigmas_from(const Eigen::Vector2d& g0,
                         const Eigen::Matrix2d& g0_covariance = Eigen::Matrix2d::Zero()) const;
  // (b1, b2) and the covariance gap_sigmas() weighs them with; false (both
  // untouched or partly set) before valid() or while a batch fit is singular.
  bool gap_fit(Eigen::Vector2d& g, Eigen::Matrix2d& cov) const;
  static constexpr int kBatches = 8;
  // valid(), gap() >= Config::min_gap and gap_sigmas() >= Config::
  // min_gap_sigmas: the pump's D_Phi is worth adding.
  bool usable() const {
    return valid() && gap() >= config_.min_gap && gap_sigmas() >= config_.min_gap_sigmas;
  }

 private:
  // A row: the pump regressors I0..I2, the known rate's integrals J0..J4
  // (model-free) and L = ln a - ln a0. y = L + p' J for the model p.
  static constexpr int kRow = 3 + kParams + 1;
  using VecR = Eigen::Matrix<double, kRow, 1>;
  using MatR = Eigen::Matrix<double, kRow, kRow>;
  using VecH = Eigen::Matrix<double, kRow - 1, 1>;
  using Mat4 = Eigen::Matrix<double, 4, 4>;
  void fold_segment();
  // The sums of the rows referred to the model p_: [N b; b' yy] of (I0..I2, y).
  Mat4 with_model(const MatR& m) const;
  // d(b1, b2)/dp: how an error in the model moves the gap harmonic.
  Eigen::Matrix<double, 2, kParams> model_shift() const;
  // The fit's derived figures, recomputed only when m_ or the model changes:
  // the control-rate task asks for them every sample and an eigen-solve each
  // time cost more than the rest of the estimator.
  void refresh_fit();

  Config config_{};
  ParamVector p_ = ParamVector::Zero();
  ParamMatrix p_cov_ = ParamMatrix::Zero();
  MatR m_ = MatR::Zero();             // sum of r r' (per segment, centred) over folded segments
  std::array<MatR, kBatches> batch_;  // the same sums over segments n, n + kBatches, ...
  uint32_t segments_{0};              // segments folded
  double fit_s_{0};
  double t_last_fold_s_{0};
  bool have_fold_{false};
  // present segment
  bool started_{false};
  double t0_s_{0};
  double t_last_s_{0};
  double ln_a0_{0};
  VecH z_{VecH::Zero()};       // integrals I0..I2, J0..J4
  VecH h_prev_{VecH::Zero()};  // their integrands at the previous sample
  VecR block_{VecR::Zero()};
  int in_block_{0};
  MatR seg_s_{MatR::Zero()};
  VecR seg_sum_{VecR::Zero()};
  int seg_blocks_{0};
  double w_last_{0};
  // The last pump_lag_samples + 1 pumps w (ring, the newest at w_pos_), and
  // how many since the last restart (up to pump_lag_samples + 1): the first
  // row after a restart waits for its pump.
  std::array<double, kMaxPumpLag + 1> w_ring_{};
  std::size_t w_pos_{0};
  int w_count_{0};
  // refresh_fit(): kappa_2 of m_'s 3x3, the coefficients and gap_sigmas()
  // (zero until valid).
  double kappa_2_{std::numeric_limits<double>::infinity()};
  bool conditioned_{false};  // kappa_2_ has been within Config::max_kappa_2 (valid())
  Eigen::Vector3d coefficients_{Eigen::Vector3d::Zero()};
  double gap_sigmas_{0};
};

}  // namespace hrg::est
