// SPDX-License-Identifier: MIT
#pragma once

// Parameters of the simulated resonator, its electrodes and the effects the
// baseline model leaves out (docs/effects-catalog.md). Shared by the full-rate
// Resonator and the AveragedModel so that both describe the same instrument.
//
// Units: SI inside (s, Hz, rad, rad/s, degC). The Effects members keep the
// catalogue's parameter names and units (deg, ppm/degC, Hz/V^2, ...) because
// the audit tool reports them in those units. Signals x = C and y = D are in
// volts of pickoff output; forces are in V/s^2 (acceleration of the pickoff
// signal), so gains have units 1/s^2 per volt (or per volt squared).

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hrg::sim {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kEarthRateRadS = 7.2921159e-5;  // sidereal rotation of the Earth

// The seed's example resonator (section 2): f = 5 kHz, Q = 5e6, dQ/Q = 0.1
// (dmu = 0.05, since dQ/Q ~ 2 dmu), split 5e-4 Hz, axes at zero.
struct ResonatorParams {
  double f_hz = 5000.0;  // mean resonance frequency at temp_ref_c
  double q = 5.0e6;      // mean quality factor: nu = pi f / q (amplitude decay rate)
  double dmu = 0.05;  // damping anisotropy: a wave at theta decays at nu(1+dmu cos4(theta-th_mu))
  double th_mu_rad = 0.0;       // physical angle of the most damped axis
  double split_hz = 5.0e-4;     // f_p - f_q; the stiff (higher) axis is at th_w
  double th_w_rad = 0.0;        // physical angle of the stiff axis
  double angular_gain = 0.554;  // K: free precession theta_A' = -K Omega / 2
  double temp_ref_c = 25.0;     // T0 of the thermal effects

  double omega_rad_s() const { return 2.0 * kPi * f_hz; }
  double nu_per_s() const { return kPi * f_hz / q; }
  // dw = |w_p - w_q| / 2 of physics.md (half the split, rad/s), signed like split_hz.
  double half_split_rad_s() const { return kPi * split_hz; }
};

// Electrodes. The ring electrode (pump) force is K_Phi0 V^2 / d^2 (seed eq. 25)
// linearised in W: F = k_pump V(t)^2 G [x, y] with the gap pattern
// 1/d0^3 ~ 1 + eps_p cos4theta + eps_q sin4theta (instrument axes), whose
// n = 2 projection is G = [[1 + eps_p/2, eps_q/2], [eps_q/2, 1 - eps_p/2]].
// With V = V0 cos(w t + phi) the 2w part of V^2 pumps (growth rate
// k_pump V0^2 / (8 w) at the best phase) and the DC part V0^2/2 is the
// electrostatic spring (Effects::electrostatic_spring).
//
// Default k_pump = 4 w^2 / (9 Q) = 87.73 1/(s^2 V^2): the parametric threshold
// of the default resonator, V0 = sqrt(8 w nu / k_pump), is 3.00 V.
// Default forcer gain 200 1/s^2: a 1 V forcer envelope in phase with the
// velocity holds a wave of 200 / (2 w nu) = 1.01 V against the mean damping.
struct ElectrodeParams {
  double pump_gain_per_s2_v2 = 87.73;  // k_pump, 1/(s^2 V^2)
  double eps_p = 0.0;                  // 4th harmonic of 1/d0^3, cos part (instrument axes)
  double eps_q = 0.0;                  // 4th harmonic of 1/d0^3, sin part
  double forcer_gain_per_s2 = 200.0;   // F_x = g V_fx, F_y = g V_fy (V/s^2 per V)

  // Parametric threshold amplitude for a wave decaying at nu_eff (1/s).
  double threshold_v(double omega_rad_s, double nu_eff_per_s) const {
    return std::sqrt(8.0 * omega_rad_s * nu_eff_per_s / pump_gain_per_s2_v2);
  }
  // The electrostatic spring this pump gain implies: df = c V0^2 with
  // c = -k_pump / (8 pi w) (Hz/V^2, negative = softer).
  double physical_spring_hz_per_v2(double omega_rad_s) const {
    return -pump_gain_per_s2_v2 / (8.0 * kPi * omega_rad_s);
  }
};

// ---- Effects of docs/effects-catalog.md: one member each, all off by default.

struct PickoffGainMismatch {
  static constexpr const char* kId = "pickoff_gain_mismatch";
  bool enabled = false;
  double gain = 0.0;  // y_meas = (1 + gain) y  (-)
};

struct PickoffPhaseMismatch {
  static constexpr const char* kId = "pickoff_phase_mismatch";
  bool enabled = false;
  double phase_deg = 0.0;  // Y_meas = Y e^{-i phase}: y chain lags x (deg)
};

struct PickoffMisalignment {
  static constexpr const char* kId = "pickoff_misalignment";
  bool enabled = false;
  double angle_deg = 0.0;  // y_meas = y cos2b + x sin2b, b physical (deg)
};

struct DuffingStiffness {
  static constexpr const char* kId = "duffing_stiffness";
  bool enabled = false;
  double hz_per_v2 = 0.0;  // a standing wave of amplitude a rings c a^2 higher (Hz/V^2)
  // Cubic stiffness kappa of F = -kappa (x^2+y^2)[x,y]: c = 3 kappa / (16 pi w).
  double kappa_per_s2_v2(double omega_rad_s) const {
    return 16.0 * kPi * omega_rad_s * hz_per_v2 / 3.0;
  }
};

struct NonlinearDamping {
  static constexpr const char* kId = "nonlinear_damping";
  bool enabled = false;
  double rel_per_v2 =
      0.0;  // damping scales by (1 + eta a^2), a^2 taken as E = a_A^2 + a_B^2 (1/V^2)
};

struct ThermalFrequency {
  static constexpr const char* kId = "thermal_frequency";
  bool enabled = false;
  double ppm_per_c = 0.0;  // f(T) = f(T0)(1 + alpha (T - T0)) (ppm/degC)
};

struct ThermalDamping {
  static constexpr const char* kId = "thermal_damping";
  bool enabled = false;
  double rel_per_c = 0.0;  // damping scales by (1 + beta (T - T0)) (1/degC)
};

struct ElectrostaticSpring {
  static constexpr const char* kId = "electrostatic_spring";
  bool enabled = false;
  // Frequency shift c V_pump^2 while the pump runs (Hz/V^2, negative = softer).
  // The physical value of the default electrodes is
  // ElectrodeParams::physical_spring_hz_per_v2 (-1.11e-4 Hz/V^2). Off = the
  // seed's model, which drops the DC part of V^2.
  double hz_per_v2 = 0.0;
};

struct DriveFeedthrough {
  static constexpr const char* kId = "drive_feedthrough";
  bool enabled = false;
  // Each pickoff gains c_k V_pump e^{i(phase_drive + psi_k)} while exc = 1.
  double x_v_per_v = 0.0;
  double y_v_per_v = 0.0;
  double x_phase_deg = 0.0;
  double y_phase_deg = 0.0;
  // The catalogue's single parameter: the larger of |c_x|, |c_y| (V/V).
  double v_per_v() const { return std::max(std::abs(x_v_per_v), std::abs(y_v_per_v)); }
};

struct Effects {
  PickoffGainMismatch pickoff_gain_mismatch;
  PickoffPhaseMismatch pickoff_phase_mismatch;
  PickoffMisalignment pickoff_misalignment;
  DuffingStiffness duffing_stiffness;
  NonlinearDamping nonlinear_damping;
  ThermalFrequency thermal_frequency;
  ThermalDamping thermal_damping;
  ElectrostaticSpring electrostatic_spring;
  DriveFeedthrough drive_feedthrough;
};

// Catalogue ids in the catalogue's order.
inline constexpr const char* kEffectIds[] = {
    PickoffGainMismatch::kId, PickoffPhaseMismatch::kId, PickoffMisalignment::kId,
    DuffingStiffness::kId,    NonlinearDamping::kId,     ThermalFrequency::kId,
    ThermalDamping::kId,      ElectrostaticSpring::kId,  DriveFeedthrough::kId,
};

}  // namespace hrg::sim
