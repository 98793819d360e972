// SPDX-License-Identifier: MIT
#pragma once

// The fitted model: the seed's averaged equations (physics.md section 2) in
// the carrier frame, Z' = A Z with
//   A = i(dw0 I + dw [c4w s4w; s4w -c4w]) - s (nu I + [dnuC dnuS; dnuS -dnuC])
//       + (Omega K + (2 pi / 3) c Q) [0 1; -1 0],
// measured through the pickoff matrix C (gain, phase, misalignment), plus the
// catalogue's extensions as extra parameters that start at zero (a Duffing
// term c both shifts dw0 by 2 pi c a_A^2 and turns the pattern through the
// quadrature Q = 2 a_A a_B of each block, read through C's inverse). Each
// free-decay segment has its own initial state, solved by linear least
// squares inside every evaluation (variable projection).

#include <array>
#include <complex>
#include <vector>

#include "dataset.hpp"

namespace hrg::audit::detail {

enum Param : int {
  kDw0,    // wave frequency minus the carrier frame, rad/s
  kNu,     // mean amplitude decay rate, 1/s
  kDnuC,   // nu dmu cos 4th_mu, 1/s
  kDnuS,   // nu dmu sin 4th_mu, 1/s
  kDwC,    // dw cos 4th_w (half split), rad/s
  kDwS,    // dw sin 4th_w, rad/s
  kK,      // angular gain
  kGain,   // pickoff_gain_mismatch, -
  kPhase,  // pickoff_phase_mismatch, rad
  kMis,    // pickoff_misalignment, rad (physical)
  kDuff,   // duffing_stiffness, Hz/V^2
  kNld,    // nonlinear_damping, 1/V^2
  kTf,     // thermal_frequency, ppm/degC
  kTd,     // thermal_damping, 1/degC
  kEs,     // electrostatic_spring, Hz/V^2
  kGapP,   // gap_harmonics eps_p: 1/d0^3 ~ 1 + eps_p cos4th + eps_q sin4th (instrument axes)
  kGapQ,   // gap_harmonics eps_q
  kCor,    // factor on the second-order Coriolis shift (Omega K)^2/2w: 1 for eq. 1;
           // fitted as a nuisance because first-order averaged simulators leave it out
  // Generic terms of the description of what the catalogue cannot name
  // (description.cpp); never a catalogue effect, never a calibration.
  kGFreqA4,     // frequency per a_A^4, Hz/V^4
  kGDampA4,     // damping scale per a_A^4, 1/V^4
  kGFreqT2,     // frequency per (T - T0)^2, ppm/degC^2
  kGDampT2,     // damping scale per (T - T0)^2, 1/degC^2
  kGFreqTime,   // frequency drift, Hz/h (about the recording's middle)
  kGDampTime,   // damping scale drift, 1/h
  kGDamp8C,     // damping scale, cos 8 theta part
  kGDamp8S,     // damping scale, sin 8 theta part
  kGFreq8C,     // frequency, cos 8 theta part, Hz
  kGFreq8S,     // frequency, sin 8 theta part, Hz
  kGGainTime,   // y/x pickoff gain ratio drift, 1/h
  kGPhaseTime,  // y pickoff phase drift, rad/h
  kGGainTemp,   // y/x pickoff gain ratio per degC, 1/degC
  kGOffXRe,     // additive offset of the x pickoff (cx_v), V
  kGOffXIm,     // additive offset of the x pickoff (-sx_v), V
  kGOffYRe,     // additive offset of the y pickoff (cy_v), V
  kGOffYIm,     // additive offset of the y pickoff (-sy_v), V
  kGFreqExc,    // frequency offset while the excitation is on, Hz
  kParamCount
};
inline constexpr int kFirstGeneric = kGFreqA4;

using Params = std::array<double, kParamCount>;
using Mask = std::array<bool, kParamCount>;

// Typical magnitude of each parameter: sets finite-difference steps and scaling.
double param_scale(int p);

struct EvalOptions {
  bool include_heldout = true;  // fit segments marked heldout too
  bool heldout_only = false;    // residuals of held-out segments, state from their first 20 %
  bool use_forced = false;      // add the excitation-segment frequencies (weights sigma_rad_s)
};

// Residual vector in units of the noise: 4 per block (re/im of x, y) scaled
// by sqrt(n)/noise, then one per excitation segment (frequency / sigma_rad_s),
// then one per excitation segment with a balance weight (balance / its sigma).
// `pred`, when given, receives the predicted measured block means (x, y).
void evaluate(const Dataset& d, const Params& p, const EvalOptions& o, std::vector<double>& res,
              std::vector<std::array<cplx, 2>>* pred = nullptr);

// Frequency residuals (rad/s) of the excitation segments alone.
std::vector<double> forced_residuals(const Dataset& d, const Params& p);

// The pull of a drive feedthrough c (Re, Im of c_x, c_y in the frame of the
// wave phase) on the true frequency of excitation segment f, rad/s: the pump
// follows the measured wave phase, which the feedthrough turns by delta =
// Im(V (c_x cos 2 theta + c_y sin 2 theta)) / a_A off the true one, so its
// parametric drive at twice the phase is 2 delta off and pulls the frequency
// by G sin 2 delta ~ 2 delta G, G the pump's share of the growth, (a_A'/a_A +
// nu) V^2 / mean V^2 (physics.md section 4; tools/audit/README.md step 2).
double pump_phase_pull(const ForcedSegment& f, const std::array<double, 4>& c, double nu_per_s);

// Amplitude balance of the excitation segments (1/s): the AGC holds a_A, so
//   ln a_A(t1) - ln a_A(t0) + int s (nu + dnu_C c4 + dnu_S s4) dt
//     = c int V^2 (1 + eps_p/2 c4 + eps_q/2 s4) dt
// (the ring pump's in-phase force through the gap pattern G, seed eqs. 25-27;
// s the damping scale of the thermal and nonlinear terms), per unit time. The
// pump gain c is a nuisance, solved by weighted least squares inside every
// evaluation (with its change while the loop recovers, PumpGain). Empty
// unless the segments have their balance weights.
std::vector<double> balance_residuals(const Dataset& d, const Params& p);
// The left side of the balance per segment (1/s) and the pump gain of the
// weighted fit (1/(s V^2)): c = c0 + c1 a_A'/a_A, the pump's efficiency
// while the amplitude loop recovers from a window (its phase settling) is
// not the one while it holds. Where the recovering segments are used (fewer
// than ten held), the few held among them (ForcedSegment::pump_settled) have
// a gain of their own, c_settled: the firmware's telemetry holds one, the
// still segment at the run's end, 5 % above the recovering segments' line at
// a_A'/a_A = 0 (design 11 of `audit-bench --seed 2026`), and through the line
// that offset read as a damping anisotropy at its angle, so as a pickoff
// misalignment of about -0.006 deg (tools/audit/README.md, step 3).
std::vector<double> balance_left(const Dataset& d, const Params& p);
// The true vibration's growth a_A'/a_A over excitation segment f (1/s): its
// measured growth less the change the pickoff map's readout makes between
// the rows its ends average (a gain g shows a_A (1 + g sin^2 2theta), a
// misalignment b a_A (1 + b sin 4theta)). The pump's efficiency and the
// pump's pull follow the true vibration; at the measured growth the pump's
// law read a gain's readout 2 g theta' sin 4theta as its efficiency.
double true_growth_per_s(const ForcedSegment& f, const Params& p);
struct PumpGain {
  double c0 = 0.0, c1 = 0.0, c_settled = 0.0;
  double at(const ForcedSegment& f, double growth_per_s) const {
    return f.pump_settled ? c_settled : c0 + c1 * growth_per_s;
  }
};
PumpGain balance_pump_gain(const Dataset& d, const Params& p, const std::vector<double>& left);

// Pattern-angle drift of the same segments (rad/s): measured
// (theta1 - theta0) / angle_span_s (single end rows over their own span), less
// a drive feedthrough's angle_pull_rad_s, against Omega K = -2 theta' + D
// (physics.md; Omega the rate's integral over that span, angle_rate_rad_s) with
//   D = s (dnu_C sin4th - dnu_S cos4th) + c V^2 (eps_q/2 cos4th - eps_p/2 sin4th)
// (the damping anisotropy's drift and the pump's through the gap, c from the
// balance) and the pickoff map's readout distortion at both ends. One per
// segment with an angle weight.
std::vector<double> angle_residuals(const Dataset& d, const Params& p);

// exp(A t) of a 2x2 complex matrix (closed form).
using Mat2 = std::array<cplx, 4>;  // row-major
Mat2 expm2(const Mat2& a, double t);

// The model's measured envelopes at row times `rows` of free segment `seg`
// (extrapolated with the segment's own dynamics and fitted initial state),
// and at the first of them the A wave's phase and pattern angle theta_A in
// (-pi/4, pi/4] (each where asked for).
std::vector<std::array<cplx, 2>> predict_rows(const Dataset& d, const Params& p, std::size_t seg,
                                              const std::vector<std::size_t>& rows,
                                              double* wave_phase_rad, double* theta_rad = nullptr);

}  // namespace hrg::audit::detail
