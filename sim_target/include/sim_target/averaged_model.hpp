// SPDX-License-Identifier: MIT
#pragma once

// Averaged (complex-envelope) resonator model, physics.md section 2:
//
//   x = Re(X e^{i w_ref t}),  y = Re(Y e^{i w_ref t}),  Z = [X, Y]  (V of pickoff)
//   Z' = i(w - w_ref) Z + (i/2w)(Kmat - w^2) Z - 1/2 (Dmat + G) Z + F / (2 i w)
//
// with the same parameters and effects as the full-rate Resonator. The pump
// voltage V(t) = Re(Vc e^{i w_ref t}) enters through V^2: its 2w part gives the
// parametric term -i k_pump Vc^2 / (8 w) G Z*, its DC part (electrostatic
// spring, when enabled) -i k_s |Vc|^2 / (4 w) G Z. Forcers enter as
// -i g Fxy / (2 w).
//
// Integration: the slow equations are linear in (Z, Z*) for frozen
// coefficients, so each step applies the exact propagator expm(A h) of the
// 5x5 real system [Re X, Im X, Re Y, Im Y, 1]. With constant inputs (rate,
// temperature, drive) and no amplitude-dependent effect, a call to advance()
// is one exact step whatever its length, and the propagator is cached. With
// time-varying profiles the coefficients are taken at the step's midpoint
// (second order); with amplitude- or phase-dependent terms (Duffing, nonlinear
// damping, drive phase following the wave) at a predicted midpoint state.
// Steps are at most max_step_s (default 0.01 s) in those cases. Steps never
// straddle a corner of a profile (a rate step is applied at its exact time),
// and a stepwise-constant profile costs one exact step per segment.
//
// Not thread-safe; cheap to copy (Monte Carlo copies one per run).

#include <complex>

#include <Eigen/Dense>

#include "sim_target/params.hpp"
#include "sim_target/profile.hpp"

namespace hrg::sim {

using cplx = std::complex<double>;

// Drive in envelope form. Phases are envelope phases relative to the model's
// reference e^{i w_ref t}, or relative to the temporal phase phi_A of the
// A wave when the matching *_follows_wave flag is set (X ~ a_A cos2theta e^{i phi_A}).
// Best pumping (growth k_pump V0^2/(8w)) is at pump_phase_rad = +pi/4 relative
// to the wave (mod pi); -pi/4 damps.
struct EnvelopeDrive {
  bool excitation = false;      // false: pump and forcers output zero (free decay)
  double pump_v = 0.0;          // V0, amplitude of the ring-electrode voltage (V)
  double pump_phase_rad = 0.0;  // envelope phase of the pump voltage (rad)
  bool pump_follows_wave = true;
  cplx forcer_x_v{};  // forcer x voltage envelope: V_fx = Re(Fx e^{i w_ref t}) (V)
  cplx forcer_y_v{};  // forcer y voltage envelope (V)
  bool forcers_follow_wave = false;
};

// Wave variables of physics.md section 2 (V^2 for E, R, S, Q).
struct WaveState {
  double energy_v2 = 0.0;  // E = a_A^2 + a_B^2
  double r_v2 = 0.0;
  double s_v2 = 0.0;
  double quad_v2 = 0.0;    // Q = 2 a_A a_B
  double theta_rad = 0.0;  // theta_A = atan2(S, R) / 4 (physical)
  double a_A_v = 0.0;
  double a_B_v = 0.0;        // signed like Q
  double phase_a_rad = 0.0;  // temporal phase phi_A of the A wave
};

// Demodulated pickoffs as in docs/recording-format.md: X = cx - i sx.
struct Demodulated {
  double cx_v = 0.0;
  double sx_v = 0.0;
  double cy_v = 0.0;
  double sy_v = 0.0;
};

// One row of an hrg-recording v1 file.
struct RecordingRow {
  double t_s = 0.0;
  Demodulated d;
  int exc = 0;
  double pump_v = 0.0;
  double temp_c = 0.0;
  double rate_dps = 0.0;
};

WaveState wave_state(cplx x_env, cplx y_env);
// wave_state()'s theta_rad alone (the same operations, so the same bits), for
// the simulated board's once-per-block unwrap of the pattern angle.
double wave_angle_rad(cplx x_env, cplx y_env);

// Envelopes of a standing wave: Z = e^{i phase}(a_A [cos2th, sin2th] - i a_B [-sin2th, cos2th]),
// so that Q = 2 a_A a_B.
void standing_wave(double a_A_v, double theta_rad, double a_B_v, double phase_rad, cplx& x_env,
                   cplx& y_env);

// Measurement side of the catalogue (gain/phase mismatch, misalignment, drive
// feedthrough) applied to true envelopes. `pump_env_v` is the pump voltage
// envelope Vc (0 when the excitation is off).
void measure_envelopes(const Effects& fx, cplx x_env, cplx y_env, cplx pump_env_v, cplx& x_meas,
                       cplx& y_meas);

class AveragedModel {
 public:
  // f_ref_hz <= 0 selects params.f_hz as the model's reference frequency.
  explicit AveragedModel(const ResonatorParams& params = {}, const ElectrodeParams& electrodes = {},
                         const Effects& effects = {}, double f_ref_hz = 0.0);

  void set_params(const ResonatorParams& p);
  void set_electrodes(const ElectrodeParams& e);
  void set_effects(const Effects& fx);
  void set_rate_profile(Profile rate_rad_s);     // Omega(t), rad/s
  void set_temperature_profile(Profile temp_c);  // T(t), degC
  void set_drive(const EnvelopeDrive& drive);    // held until the next call
  void set_max_step_s(double h_s) { max_step_s_ = h_s; }
  void set_time(double t_s) { t_s_ = t_s; }

  // State. Envelopes are relative to the model's reference e^{i w_ref t}.
  void set_standing_wave(double a_A_v, double theta_rad, double a_B_v = 0.0,
                         double phase_rad = 0.0);
  void set_envelopes(cplx x_env, cplx y_env);

  // Integrates dt_s >= 0 seconds with the current drive.
  void advance(double dt_s);

  double time_s() const { return t_s_; }
  double f_ref_hz() const { return f_ref_hz_; }
  cplx x_envelope() const { return {r_(0), r_(1)}; }
  cplx y_envelope() const { return {r_(2), r_(3)}; }
  WaveState wave() const { return wave_state(x_envelope(), y_envelope()); }
  double rate_rad_s() const { return rate_.value(t_s_); }
  double temperature_c() const { return temp_.value(t_s_); }
  // Pump voltage envelope Vc applied now (0 when the excitation is off).
  cplx pump_envelope_v() const;

  // Demodulated measured outputs (with the measurement-side effects) at the
  // model's reference, or at another constant reference frequency whose phase
  // is 2 pi f_ref t.
  Demodulated demodulated() const;
  Demodulated demodulated(double f_ref_hz) const;
  RecordingRow row(double f_ref_hz) const;

 private:
  using Mat5 = Eigen::Matrix<double, 5, 5>;
  using Vec5 = Eigen::Matrix<double, 5, 1>;

  Mat5 system_matrix(double t_s, const Vec5& r) const;
  void step(double h, bool state_dep, bool inputs_vary);
  bool state_dependent() const;

  ResonatorParams params_;
  ElectrodeParams electrodes_;
  Effects effects_;
  double f_ref_hz_;
  Profile rate_;
  Profile temp_;
  EnvelopeDrive drive_;
  double max_step_s_ = 0.01;
  double t_s_ = 0.0;
  Vec5 r_ = Vec5::Zero();
  Mat5 cached_ah_ = Mat5::Zero();
  Mat5 cached_phi_ = Mat5::Identity();
  double cached_h_ = -1.0;
  bool dirty_ = true;  // a setter changed the system since cached_phi_ was built
};

}  // namespace hrg::sim
