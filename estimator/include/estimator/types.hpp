// SPDX-License-Identifier: MIT
#pragma once

// Vocabulary of the identification of damping anisotropy and frequency split
// (docs/physics.md sections 2, 3 and 5; the paper's eqs. 8-23).
//
// All quantities are SI: seconds, radians, 1/s for damping and rad/s for the
// (half) frequency split. Amplitudes are in pickoff units (volts at the
// demodulator output); the estimator only uses their ratios, so any
// consistent unit works.

#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace hrg::est {

// One control-rate (1 kHz) sample of the wave variables during a free-decay
// window, as the demodulator produces them (dsp/wave_variables.hpp).
struct WaveSample {
  double t_s{0};          // sample time, strictly increasing within a window
  double a_A_v{0};        // working wave amplitude, > 0
  double a_B_v{0};        // quadrature wave amplitude, signed like Q = 2 a_A a_B
  double theta_A_rad{0};  // pattern angle (physical), any branch
  double E_v2{0};         // a_A^2 + a_B^2, computed from the quadratures (eq. 13)
  // Known factor on the whole damping (mean and anisotropy) at this sample,
  // relative to the resonator model's reference state: the calibration's
  // thermal and nonlinear damping referred to the measured temperature and
  // amplitude (docs/effects-catalog.md). The identified nu, dnu_C, dnu_S are
  // then those of the reference state. 1: the seed's model (none known).
  double damping_scale{1};

  // P/E = (a_A^2 - a_B^2)/E: the share of the energy in the working wave, the
  // amplitude of the 4 theta pattern (R, S) = P (cos, sin) 4 theta_A that the
  // damping anisotropy and the pickoff gain act through.
  double p_over_e() const { return (a_A_v * a_A_v - a_B_v * a_B_v) / E_v2; }
};

// p = (nu, dnu_C, dnu_S, dw_C, dw_S) of eq. 20, in this order.
//   nu    mean damping (amplitude decay rate), 1/s
//   dnu_C nu dmu cos 4th_mu, dnu_S nu dmu sin 4th_mu, 1/s
//   dw_C  dw cos 4th_w,      dw_S  dw sin 4th_w,      rad/s, dw = |w_p - w_q|/2
inline constexpr int kParams = 5;
using ParamVector = Eigen::Matrix<double, kParams, 1>;
using ParamMatrix = Eigen::Matrix<double, kParams, kParams>;
// Normal equations with the right-hand side and y'y appended:
// [ H'H  H'y ; y'H  y'y ], so one symmetric 6x6 carries the whole LS state.
using AugmentedMatrix = Eigen::Matrix<double, kParams + 1, kParams + 1>;

enum Param : int { kNu = 0, kDnuC = 1, kDnuS = 2, kDwC = 3, kDwS = 4 };

// The paper's identification variants.
enum class Variant : uint8_t {
  joint = 0,         // all five parameters at once (eqs. 20-21)
  damping_only = 1,  // nu, dnu_C, dnu_S with the split taken as zero (eqs. 10-11)
  split_only = 2,    // nu, dw_C, dw_S with the damping anisotropy taken as zero (eqs. 15-16)
  alternating = 3,   // damping with split fixed, then split with damping fixed (eqs. 18-19)
};

// Outcome of a call. Callers may retry after `not_in_window`/`in_window`
// (sequencing errors); the data errors reject the sample or the window.
enum class Status : uint8_t {
  ok = 0,
  settling = 1,             // sample inside the post-switch settle time: ignored by rule
  not_in_window = 2,        // add_sample/end_window without begin_window
  in_window = 3,            // begin_window while a window is open
  time_not_increasing = 4,  // t_s <= previous sample time: sample rejected
  gap = 5,                  // t_s jumped more than the allowed gap: window aborted
  bad_sample = 6,           // non-finite value or a_A <= 0 or E <= 0: window aborted
  too_short = 7,            // fewer settled blocks than the minimum: window dropped
  no_data = 8,              // solve without enough windows
  ill_conditioned = 9,      // condition number past the threshold: estimate refused
  not_converged = 10,       // alternating scheme did not converge
};

// Number of bins of the 4theta coverage histogram (22.5 deg of 4theta each,
// i.e. 5.625 deg of pattern angle).
inline constexpr int kCoverageBins = 16;
using CoverageHistogram = std::array<double, kCoverageBins>;

}  // namespace hrg::est
