// SPDX-License-Identifier: MIT
#pragma once

// Do no harm for a calibration's damping model (thermal damping referred to
// the measured temperature, nonlinear damping to the wave's energy): does
// the known factor k on the damping (WaveSample::damping_scale) that the
// estimator's regressors and drift use make the free decays fit better, or
// worse, than the seed's model (k = 1)?
//
// Within a free-decay window (eq. 20, the calibration's model scaled by a
// factor f the data choose),
//     (ln E)' = -2 (nu + dnu_C r + dnu_S s) - 2 f nu (k - 1),
// r = R/E, s = S/E. With gamma = f nu one linear least-squares problem over
// every window (rows: block means of kModelCheckBlockSamples samples, the
// window's offset removed by centring): columns -2 t, -2 int r, -2 int s,
// -2 int (k - 1), observation ln E. f = 1: the calibration's model holds;
// f = 0: the damping does not change as it says (the seed's model fits);
// f = -1: its sign is wrong. The residual sum of squares is quadratic in f:
// the calibration's terms (f = 1) fit worse than none (f = 0) exactly when
// f_hat < 1/2. The check refutes the model when
//     (1/2 - f_hat) / sigma_f > kModelCheckSigmas,
// sigma_f from the residual (block means whiten the demodulator's coloured
// noise). False alarm: when the model is right (f = 1) or only half right
// (f >= 1/2), at most Phi(-kModelCheckSigmas) = 3.2e-5 per look (Gaussian
// residual), less the better f is seen (Phi(-(4 + 0.5 / sigma_f)) at f = 1);
// the statistic accumulates, so successive looks are strongly correlated and
// 100 windows stay below 100 x 3.2e-5. Mirror image: the model is supported
// when (f_hat - 1/2) / sigma_f > kModelCheckSigmas.
//
// The dnu (k - 1) term is left out (dnu / nu ~ dQ/Q: it moves f_hat by
// that fraction at most where the temperature follows the pattern angle).
// What the check cannot see it leaves alone: k constant across and within
// the windows (f collinear with nu), no variation at all (k = 1: nothing to
// check). The frequency terms of a calibration (thermal frequency, Duffing,
// electrostatic spring) are not used by the firmware and need no check; the
// gap harmonic has its own (est::Estimator::known_gap_refuted).
//
// Fixed-size Eigen state, no heap, no exceptions: callable from the firmware.

#include <Eigen/Core>

#include "estimator/types.hpp"

namespace hrg::est {

// Columns: nu, dnu_C, dnu_S, gamma = f nu.
inline constexpr int kModelCheckParams = 4;
// Rows are block means (10 ms at 1 kHz, longer than the demodulator's
// correlation), as in the pickoff self-calibration.
inline constexpr int kModelCheckBlockSamples = 10;
// One-sided test size: Phi(-4) = 3.2e-5.
inline constexpr double kModelCheckSigmas = 4.0;
// Windows before any verdict (the anisotropy needs angles to be told apart).
inline constexpr int kModelCheckMinWindows = 3;

struct DampingModelCheckResult {
  Status status = Status::no_data;  // no_data: nothing known to check (k = 1) or too few windows
  double factor = 0.0;              // f_hat: how much of the calibration's damping change is seen
  double factor_sigma = 0.0;        // 1 sigma, from the residual
  double nu_per_s = 0.0;            // the reference damping solved alongside (1/s)
  bool refuted = false;             // its terms fit significantly worse than none
  bool supported = false;           // significantly better than none: (f - 1/2) / sigma_f > z
  int windows = 0;
};

class DampingModelCheck {
 public:
  using Aug = Eigen::Matrix<double, kModelCheckParams + 1, kModelCheckParams + 1>;
  using Vec = Eigen::Matrix<double, kModelCheckParams + 1, 1>;

  void reset() { *this = DampingModelCheck{}; }
  void begin_window();
  // One sample the estimator's accumulator took (t_s strictly increasing).
  Status add_sample(const WaveSample& s);
  void abort_window() { open_ = false; }
  // Folds the window (too_short below 3 blocks); a partial last block is left out.
  Status end_window();
  DampingModelCheckResult solve() const;

 private:
  void fold_block();

  Vec sum_ = Vec::Zero();  // the window's raw sums
  Aug sum2_ = Aug::Zero();
  Vec block_ = Vec::Zero();
  int in_block_ = 0;
  int blocks_in_window_ = 0;
  int samples_in_window_ = 0;
  bool open_ = false;
  double t0_ = 0.0;
  double y0_ = 0.0;
  double last_t_ = 0.0;
  double last_r_ = 0.0;
  double last_s_ = 0.0;
  double last_k_ = 0.0;
  double int_r_ = 0.0;
  double int_s_ = 0.0;
  double int_k_ = 0.0;   // of k - 1
  double max_dk_ = 0.0;  // largest |k - 1| seen: zero, nothing to check
  Aug a_ = Aug::Zero();  // over the windows, centred
  int windows_ = 0;
  int blocks_ = 0;
};

}  // namespace hrg::est
