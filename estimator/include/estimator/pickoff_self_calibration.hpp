// SPDX-License-Identifier: MIT
#pragma once

// Online identification of the pickoff gain mismatch g and misalignment b
// from the estimator's own free-decay windows (docs/effects-catalog.md).
//
// Through the map Y_meas = (1 + g)(cos2b Y + sin2b X), a standing wave of
// amplitude a at angle theta is measured with
//     E_meas = a^2 [cos^2 2th + (1 + g)^2 sin^2(2th + 2b)]
//           ~= a^2 [1 + g (1 - cos 4th) + 2b sin 4th]      (first order),
// a 4theta pattern in the LEVEL of ln E. Damping anisotropy is a 4theta
// pattern in the decay RATE instead (eq. 8 with a_B ~ 0: a_A' = -(nu + d) a_A,
// d = dnu_C cos4th + dnu_S sin4th). Within window w:
//     ln E(t) = c_w - 2 nu t - 2 dnu_C int cos4th dt - 2 dnu_S int sin4th dt
//               - g cos4th + 2b sin4th.
// The window's offset c_w (the amplitude it starts at, and the constant g)
// is removed by centring every regressor within its window; the rest is one
// least-squares problem in p = (nu, dnu_C, dnu_S, g, b) over all windows.
// Observability: at rest the level pattern is constant within a window (its
// regressors centre to zero); at one constant turn rate w the integrals of a
// 4theta pattern are 4theta patterns themselves, so -4 g w sin4th looks
// exactly like a damping anisotropy (the error the seed's method makes). g
// and b separate from the anisotropy only with windows at different rates,
// at rest included; the condition check refuses the solve otherwise. The
// phase mismatch leaves E unchanged and is not seen here (it shows in the
// quadrature). The model is first order: its bias is O(g^2, g b); applied
// and identified again on the corrected signals, it shrinks quadratically.
//
// Fixed-size Eigen state, no heap, no exceptions: callable from the firmware.

#include <Eigen/Core>

#include "estimator/types.hpp"

namespace hrg::est {

inline constexpr int kSelfCalParams = 5;  // nu, dnu_C, dnu_S, g, b
// Largest condition number (Jacobi-scaled) a solve is accepted with.
inline constexpr double kSelfCalMaxKappa = 1e4;
// A window counts as turning when 4theta moved by at least this much (net,
// so measurement noise does not add up): 0.1 rad is 1.4 deg of pattern angle.
inline constexpr double kSelfCalMinTurnRad = 0.1;

struct PickoffSelfCalResult {
  Status status = Status::no_data;
  double gain = 0.0;              // g (-)
  double gain_sigma = 0.0;        // 1 sigma, from the residual
  double misalignment_rad = 0.0;  // b (rad, physical)
  double misalignment_sigma_rad = 0.0;
  double nu_per_s = 0.0;  // the damping terms solved alongside (1/s)
  double dnu_c_per_s = 0.0;
  double dnu_s_per_s = 0.0;
  double kappa_2 = 0.0;       // condition number of the Jacobi-scaled normal matrix
  double residual_rms = 0.0;  // of ln E
  int windows = 0;
  int turning_windows = 0;  // windows whose 4theta moved by kSelfCalMinTurnRad or more
  int samples = 0;
};

class PickoffSelfCalibration {
 public:
  using Vec = Eigen::Matrix<double, kSelfCalParams, 1>;
  using Mat = Eigen::Matrix<double, kSelfCalParams, kSelfCalParams>;

  void reset();
  Status begin_window();
  // One control-rate sample inside the window (t_s strictly increasing).
  Status add_sample(const WaveSample& s);
  // Drops the open window (cut short by a fault): nothing of it is folded.
  void abort_window() { open_ = false; }
  // Folds the window into the normal equations (too_short below min_samples).
  Status end_window(int min_samples = 50);
  // Solves; ill_conditioned when no window turned (g and b unseen) or when
  // kappa_2 exceeds max_kappa (the windows' turn rates did not vary enough
  // to tell g and b from the damping).
  PickoffSelfCalResult solve(double max_kappa = kSelfCalMaxKappa) const;

 private:
  // Per-window raw sums of the regressors z and the observation y.
  Vec sz_ = Vec::Zero();
  Mat szz_ = Mat::Zero();
  Vec szy_ = Vec::Zero();
  double sy_ = 0.0;
  double syy_ = 0.0;
  int n_ = 0;
  bool open_ = false;
  double t0_ = 0.0;
  double last_t_ = 0.0;
  double last_c4_ = 0.0;
  double last_s4_ = 0.0;
  double int_c4_ = 0.0;
  double int_s4_ = 0.0;
  double last_4th_ = 0.0;
  double turn_4th_ = 0.0;  // net change of 4theta within the window
  // Centred normal equations over the windows.
  Mat hh_ = Mat::Zero();
  Vec hy_ = Vec::Zero();
  double yy_ = 0.0;
  int windows_ = 0;
  int turning_ = 0;
  int samples_ = 0;
};

}  // namespace hrg::est
