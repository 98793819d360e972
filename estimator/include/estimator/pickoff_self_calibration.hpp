// SPDX-License-Identifier: MIT
#pragma once

// Online identification of the pickoff map (gain mismatch g, misalignment b,
// phase lag phi; docs/effects-catalog.md) from the estimator's own
// free-decay windows.
//
// Level of E. Through Y_meas = (1 + g) e^{-i phi}(cos2b Y + sin2b X) the
// corrected energy is a linear form in the measured E, R, S (dsp/
// pickoff_correction.hpp), E ~ E_m + rho R_m - sin2b sqrt(1 - rho^2) S_m, so
// with r = R/E and s = S/E of the measurement, exactly,
//     ln E_meas = ln E - ln(1 + u) + const,  u = rho r - 2 bh s,
//     rho = (k - 1)/(k + 1), k = (1 + g)^2,  bh = sin2b sqrt(1 - rho^2) / 2
// (bh was sin2b / (2 sqrt(1 - rho^2)): b read 1 - rho^2 short, 8.7e-4 of it
// at g 3 %). With x = 4theta, u = A cos(x + delta) (A e^{i delta} = rho +
// 2i bh, and r + is = e^{ix} to O(q^2) of the quadrature), and
//     -ln(1 + u) = -2 Re ln(1 + w e^{ix}) + const,
//     w = beta e^{i delta},  beta = A / (1 + sqrt(1 - A^2)),
// exactly: its harmonics are -2 beta cos(x + delta) (4theta),
// +beta^2 cos 2(x + delta) (8theta), -(2/3) beta^3 cos 3(x + delta) (12theta),
// ... The fit holds the first three:
//     -rho_f r + 2 bh_f s                    (rho_f + 2i bh_f = 2 w),
//     + h_c (r^2 - s^2)/2 + h_s r s          (h_c - i h_s = 2 w^2),
//     + k_c (r^3 - 3 r s^2) + k_s (3 r^2 s - s^3)  (k_c - i k_s = -(2/3) w^3),
// the 4 and 8theta pairs free, the 12theta pair held at the value the
// fitted 4theta pair gives (w = rho_f/2 + i bh_f; two passes), so that it
// costs the map no information (free, it raised the misalignment's sigma by
// 21 % on 1 s windows). It reads the map from the 4theta pair:
// |w|^2 = rho_f^2/4 + bh_f^2, and
// (rho, bh) = (rho_f, bh_f) / (1 + |w|^2) (2 beta / A = 1 + beta^2). The
// 16theta harmonic left out is beta^4/2 (5e-8 at 1 deg, 1.5e-7 at g 5 %).
// A model that stopped at u^2/2 read the 4theta pattern scaled by
// 1 + A^2/4 (the 4theta part of -u^3/3) as the map, 3e-4 of it at b 1 deg,
// and left the 12theta part, A^3/12, in the residual, a pattern that changes
// within a turning window.
//
// Rate of E. Damping anisotropy is a 4theta pattern in the decay RATE
// (eq. 20: (ln E)' = -2 nu - 2 dnu_C r_t - 2 dnu_S s_t), of the TRUE pattern's
// r_t, s_t. The map moves them: by a rotation of x by 2b (the misalignment's;
// the fit reads dnu in the measured frame, turned by 2b) and by a boost,
// r_t - r = rho - r u, s_t - s = -2 bh - s u to first order, which adds
// -2 dnu.(r_t - r) = C + an 8theta rate pattern to (ln E)': a constant
// C = -rho dnu_C + 2 bh dnu_S (read as nu - C/2) and
//     -2 m_c int (r^2 - s^2)/2 - 2 m_s int rs,
//     m_c = -(rho dnu_C + 2 bh dnu_S),  m_s = -(rho dnu_S - 2 bh dnu_C),
// an anisotropy at 8theta that changes each window's slope with its angle
// (b 1 deg, dnu 1.6e-4 1/s: 5.4e-6 1/s). The fit holds m_c, m_s at the
// values of its fitted map and dnu, like the 12theta pair; left
// out, they and the cubic failed the decay test of 5 s windows (synthetic,
// b 1 deg: F 101 against 1.9, tests/estimator/test_pickoff_self_calibration
// .cpp; the 4.2 kHz resonator, 1800 s: 8.18 against 1.69, tools/gregory/
// README.md, "Another resonator"). Within window w:
//     ln E(t) = c_w - 2 nu t - 2 dnu_C int r - 2 dnu_S int s
//               - rho_f r + 2 bh_f s + h_c (r^2 - s^2)/2 + h_s r s
//               + k_c (r^3 - 3 r s^2) + k_s (3 r^2 s - s^3)
//               - 2 m_c int (r^2 - s^2)/2 - 2 m_s int rs.
// The window's offset c_w is removed by centring every column within the
// window; the rest is one least-squares problem over all windows.
//
// Level of the quadrature. The phase lag puts Q_meas = 2(1 + g) a^2 cos2th
// sin(2th + 2b) sin phi ~ a^2 phi sin4th into the quadrature reading, while
// the split grows the true one (eq. 20: (2 a_B/a_A)' = 2 dw_C sin4th -
// 2 dw_S cos4th):
//     Q/E (t) = c'_w + 2 dw_C int sin4th - 2 dw_S int cos4th + phi sin4th.
// The quadrature loop nulls Q_meas in operation, i.e. leaves a true
// quadrature -phi a^2 sin4th that the window starts from (the constant c'_w);
// within the window the level term follows the pattern angle. The map
// enters this row twice more: the split acts at the true angle, x_t - x =
// -rho s - 2 bh r (and the turn by 2b, read into dw), which adds a slope
// -(rho dw_S + 2 bh dw_C) and an 8theta rate pattern -2 (2 bh dw_C -
// rho dw_S) int (r^2 - s^2)/2 - 2 (rho dw_C + 2 bh dw_S) int rs to Q/E; and
// the level: Q/E ~ (1 + u) q_t, u q = rho r q - 2 bh s q. These columns are
// accumulated and held at the values of the level row's (rho_f, bh_f) and
// the fitted split (two passes), not fitted: dw and phi keep their
// information. Without them b 1 deg read phi -0.0041 +- 8e-5 deg (5 s
// windows) and -0.0117 deg on the 4.2 kHz resonator (1800 s); with them,
// -3.0e-5 +- 4.9e-6 (what is left is second order: -1.1e-4 at 2 deg). phi's
// own cross terms with g and b cancel to first order (phi (s_t + sin2b
// (1 + r_t)) (1 + u) = phi s); the row's scale 1/(sqrt(1 - rho^2) cos2b) is
// second order.
//
// Rows are block means (kSelfCalBlockSamples).
//
// Observability: at rest the level patterns are constant within a window
// (their columns centre to zero); at one constant turn rate w the integrals
// of a 4theta pattern are 4theta patterns themselves, so -4 rho w sin4th looks
// exactly like a damping anisotropy (the error the seed's method makes), and
// phi like a split. They separate only with windows at different rates, at
// rest included; the condition check refuses the solve otherwise.
//
// The decay model's one nu is what makes the level pattern observable in a
// turning window (the pattern's change within the window is mostly a slope):
// a damping that differs between windows (temperature, amplitude) shifts
// their slopes and, where it correlates with the windows' pattern angles,
// reads as a gain or misalignment. The same normal equations with a decay
// slope of their own per window (nu per window) test it: their residual
// against the common-nu fit's, F = [(RSS_c - RSS_w)/(W - 1)] / [RSS_w/dof_w],
// is ~1 when one nu holds; the result reports it (decay_f) and
// decay_consistent says whether it passed (the firmware applies nothing
// otherwise).
//
// A correction put in force changes the signals of the windows to come, not
// those already folded: refer_to_applied() re-refers the accumulated normal
// equations through it (the step's level harmonics, its nu shift -C/2 and its
// 8theta rate terms are subtracted from the observations, and the
// anisotropy's columns turned by the step's 2b, one transform of the sums),
// so the estimate keeps all the windows and reads as the residual of the
// correction in force. With the level patterns alone re-referred (the model
// before the rate terms), a step of g 3 %, b -1.5 deg left 20 + 20 windows of
// 5 s at a decay F of 386 and g 1.4e-5 off; with all of it, F 0.89 and g, b
// within 2 sigma (synthetic, tests/estimator/test_pickoff_self_calibration.cpp).
//
// Fixed-size Eigen state, no heap, no exceptions: callable from the firmware.

#include <Eigen/Core>

#include "estimator/types.hpp"

namespace hrg::est {

// Level-of-E parameters: nu, dnu_C, dnu_S, rho_f, bh_f, h_c, h_s; its
// columns add k_c, k_s, m_c, m_s, held at the values the fitted ones give
// (header).
inline constexpr int kSelfCalParams = 7;
inline constexpr int kSelfCalColumns = 11;
// Quadrature parameters: dw_C, dw_S, phi; its columns add the map's cross
// terms (the slope, the 8theta rate pair, the level pair u q), held at the
// values the level row's map and the fitted split give (header).
inline constexpr int kSelfCalQuadParams = 3;
inline constexpr int kSelfCalQuadColumns = 8;
// Rows are means over blocks of this many samples (10 ms at 1 kHz, longer
// than the demodulator's correlation): the residual then estimates the noise
// the parameters see, and the decay test is not fooled by coloured noise.
inline constexpr int kSelfCalBlockSamples = 10;
// Largest condition number (Jacobi-scaled) a solve is accepted with.
inline constexpr double kSelfCalMaxKappa = 1e4;
// A window counts as turning when 4theta moved by at least this much (net,
// so measurement noise does not add up): 0.1 rad is 1.4 deg of pattern angle.
inline constexpr double kSelfCalMinTurnRad = 0.1;
// The per-window decay test passes while F <= 1 + kSelfCalDecaySigmas *
// sqrt(2 / (W - 1)) (F's standard deviation under one common nu, W windows).
inline constexpr double kSelfCalDecaySigmas = 4.0;

struct PickoffSelfCalResult {
  Status status = Status::no_data;
  double gain = 0.0;              // g (-)
  double gain_sigma = 0.0;        // 1 sigma, from the residual
  double misalignment_rad = 0.0;  // b (rad, physical)
  double misalignment_sigma_rad = 0.0;
  double phase_rad = 0.0;  // phi: Y_meas = Y e^{-i phi} (rad)
  double phase_sigma_rad = 0.0;
  double nu_per_s = 0.0;  // the damping terms solved alongside (1/s)
  double dnu_c_per_s = 0.0;
  double dnu_s_per_s = 0.0;
  double dnu_c_sigma_per_s = 0.0;  // their 1 sigma, from the residual
  double dnu_s_sigma_per_s = 0.0;
  double level_8th_c = 0.0;  // h_c, h_s: the 8theta (O(g^2)) level terms of ln E
  double level_8th_s = 0.0;
  double level_12th_c = 0.0;  // k_c, k_s: the 12theta (O(g^3)) level terms of ln E
  double level_12th_s = 0.0;
  double rate_8th_c = 0.0;  // m_c, m_s: the 8theta decay-rate terms (1/s)
  double rate_8th_s = 0.0;
  double dw_c_rad_s = 0.0;  // the split terms of the quadrature row (rad/s)
  double dw_s_rad_s = 0.0;
  double quad_slope_per_s = 0.0;  // the quadrature row's map x split terms (header)
  double quad_rate_8th_c_per_s = 0.0;
  double quad_rate_8th_s_per_s = 0.0;
  double quad_level_r = 0.0;  // u q: rho and -2 bh as the quadrature reads them
  double quad_level_s = 0.0;
  double kappa_2 = 0.0;        // condition number of the level-of-E normal matrix (Jacobi-scaled)
  double kappa_2_quad = 0.0;   // and of the quadrature one
  double residual_rms = 0.0;   // of ln E
  double decay_f = 0.0;        // the per-window decay test's F (1 when one nu holds)
  double decay_f_limit = 0.0;  // what it passes up to
  bool decay_consistent = false;
  // The decay test's own fit (a decay rate per window): the level patterns
  // and the damping anisotropy with their 1 sigma from its residual. A
  // damping that changes between windows goes into the windows' own rates
  // there and cannot read as a level pattern, so these stand where the
  // decay test refuses the common-nu figures above.
  double per_window_gain = 0.0;
  double per_window_gain_sigma = 0.0;
  double per_window_misalignment_rad = 0.0;
  double per_window_misalignment_sigma_rad = 0.0;
  double per_window_dnu_c_per_s = 0.0;
  double per_window_dnu_s_per_s = 0.0;
  double per_window_dnu_c_sigma_per_s = 0.0;
  double per_window_dnu_s_sigma_per_s = 0.0;
  int windows = 0;
  int turning_windows = 0;  // windows whose 4theta moved by kSelfCalMinTurnRad or more
  int samples = 0;
};

// The level pattern -ln(1 + u) of a pickoff map as the fit's columns read
// it: the 4theta pair (rho_f, bh_f) and the 8theta and 12theta terms (the
// harmonics of w above, exact to the 16theta one). `misalignment_rad`
// physical; gain > -1.
struct LevelHarmonics {
  double rho_f = 0.0;
  double bh_f = 0.0;
  double h_c = 0.0;
  double h_s = 0.0;
  double k_c = 0.0;
  double k_s = 0.0;
};
LevelHarmonics level_harmonics_of(double gain, double misalignment_rad);

// Sets the terms of `step` that follow from its map and its damping: the
// 8theta and 12theta level terms (level_harmonics_of) and the 8theta rate
// terms (first order in the map: m_c = -(rho dnu_C + 2 bh dnu_S),
// m_s = -(rho dnu_S - 2 bh dnu_C)), for refer_to_applied.
void set_step_terms(PickoffSelfCalResult& step);

class PickoffSelfCalibration {
 public:
  // Augmented state of one row type: [sum z z', sum z y; ., sum y y].
  using AugE = Eigen::Matrix<double, kSelfCalColumns + 1, kSelfCalColumns + 1>;
  using AugQ = Eigen::Matrix<double, kSelfCalQuadColumns + 1, kSelfCalQuadColumns + 1>;
  using VecE = Eigen::Matrix<double, kSelfCalColumns + 1, 1>;
  using VecQ = Eigen::Matrix<double, kSelfCalQuadColumns + 1, 1>;

  void reset();
  Status begin_window();
  // One control-rate sample inside the window (t_s strictly increasing).
  Status add_sample(const WaveSample& s);
  // Drops the open window (cut short by a fault): nothing of it is folded.
  void abort_window() { open_ = false; }
  // Folds the window into the normal equations (too_short below min_samples).
  Status end_window(int min_samples = 50);
  // Solves; ill_conditioned when no window turned (g, b, phi unseen) or when
  // a kappa_2 exceeds max_kappa (the windows' turn rates did not vary enough
  // to tell the level patterns from the damping and the split).
  PickoffSelfCalResult solve(double max_kappa = kSelfCalMaxKappa) const;
  // The firmware has put `applied` (a solve's result) in force on top of the
  // correction the windows so far were taken through: their observations are
  // re-referred to the new correction (its patterns subtracted: the 4theta
  // pair of its gain and misalignment, level_harmonics_of, its 8theta and
  // 12theta level terms and 8theta rate terms as given, its nu shift from
  // its map and dnu; the anisotropy columns turned by its 2b), so later
  // solves give the residual from every window. Not inside a window.
  void refer_to_applied(const PickoffSelfCalResult& applied);

 private:
  void fold_block();

  // Per-window raw sums of [z, y] (level of E) and [zq, yq] (quadrature).
  VecE se_ = VecE::Zero();
  AugE see_ = AugE::Zero();
  VecQ sq_ = VecQ::Zero();
  AugQ sqq_ = AugQ::Zero();
  VecE block_e_ = VecE::Zero();  // the block being summed
  VecQ block_q_ = VecQ::Zero();
  int in_block_ = 0;
  int samples_in_window_ = 0;
  int n_ = 0;  // blocks in the window
  bool open_ = false;
  double t0_ = 0.0;
  double y0_ = 0.0;  // the window's first ln E (keeps the sums small)
  double last_t_ = 0.0;
  double last_r_ = 0.0;
  double last_s_ = 0.0;
  double last_c4_ = 0.0;
  double last_s4_ = 0.0;
  double int_r_ = 0.0;
  double int_s_ = 0.0;
  double int_c4_ = 0.0;
  double int_s4_ = 0.0;
  double last_c8_ = 0.0;
  double last_s8_ = 0.0;
  double int_c8_ = 0.0;
  double int_s8_ = 0.0;
  double last_4th_ = 0.0;
  double turn_4th_ = 0.0;  // net change of 4theta within the window
  // Over the windows: centred (one nu), detrended (a nu per window),
  // quadrature centred.
  AugE ae_ = AugE::Zero();
  AugE ad_ = AugE::Zero();
  AugQ aq_ = AugQ::Zero();
  int windows_ = 0;
  int turning_ = 0;
  int samples_ = 0;
  int blocks_ = 0;
};

// Do no harm for a model identified with ideal pickoffs (the seed's): how
// many standard errors its damping anisotropy (dnu_C, dnu_S of p, with their
// sigmas) stands from the one `r` solved from the same kind of windows with
// the pickoff level patterns alongside; the larger of the two components.
// A y gain mismatch g in a window while the table turns at theta' puts a
// decay rate of 4 rho theta' sin 4theta (rho ~ g) into the measured E, which
// a model without the level pattern takes for damping anisotropy (on the
// 4.2 kHz resonator of tools/gregory/README.md at g 0.01: dnu_S 1.33e-4 1/s
// against a truth of 4.87e-5, the self-calibration's 4.876e-5). 0 unless `r`
// is ok and its windows hold one decay rate (decay_consistent: otherwise a
// damping that changes between windows is what reads as a level pattern).
// Both sigmas enter as if independent: the two fits share windows, so this
// understates the significance (on the safe side for a false alarm).
double damping_anisotropy_disagreement_sigmas(const PickoffSelfCalResult& r, const ParamVector& p,
                                              double sigma_dnu_c_per_s, double sigma_dnu_s_per_s);

// How many of its own standard errors the readout's level pattern stands
// from none: the larger of |g| / sigma_g and |b| / sigma_b (the pickoff gain
// and misalignment, the two that put a 4 theta pattern into the measured
// amplitude; the phase lag reads as a split instead). 0 under the same
// conditions as above (solve not ok, or more than one decay rate).
double readout_pattern_sigmas(const PickoffSelfCalResult& r);

// How many of its own standard errors the readout's phase lag stands from
// none, |phi| / sigma_phi; 0 unless `r` is ok. The quadrature row that reads
// it holds no decay rate, so one decay rate need not hold.
double readout_phase_sigmas(const PickoffSelfCalResult& r);

// The drift a pickoff phase lag phi left uncorrected adds, against the drift
// a model p removes: 2 nu |phi| over |(dnu_C, dnu_S)|, both amplitudes of a
// 4 theta pattern in Omega K units (0 when p has no anisotropy; `r` not ok:
// 0). The loops act on the rotated readout: the pump follows a vibration
// phase off by ~ -phi sin^2 2theta, and the pattern drifts by 2 nu phi
// (measured: phi 1 deg on the 4.2 kHz resonator of tools/gregory/README.md,
// nu 1.649e-3 1/s, the seed model's ADB 21.4 deg/h = 5.75e-5 rad/s x K
// against 2 nu phi 5.76e-5). The model has no such term: its compensated
// output keeps it, and the raw output holds it beside the anisotropy's
// drift, so the compensated output can be worse than raw only when this
// share exceeds 1/2.
double readout_phase_drift_share(const PickoffSelfCalResult& r, const ParamVector& p);

}  // namespace hrg::est
