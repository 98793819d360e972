// SPDX-License-Identifier: MIT
#pragma once

// Forms the regressors of eq. 20 over one free-decay window in the integral
// (difference) form of eqs. 13 and 17, and reduces the window to its
// contribution to the normal equations.
//
// Rows. Eq. 20 multiplied by a_A and a_B and recombined gives two rows whose
// left sides are exact time derivatives of measured quantities:
//   E row  (eq. 13):  (E/2)'     = -nu E - (dnu_C cos4th + dnu_S sin4th) P
//   Q row  (eq. 17):  (a_A a_B)' = -2 nu a_A a_B + (dw_C sin4th - dw_S cos4th) P
// with P = a_A^2 - a_B^2. Integrating from the first settled sample t0,
//   E(t)/2 - E(t0)/2       = F_E(t) p,   F_E = -int [E, P c, P s, 0, 0] dt
//   a_A a_B(t) - a_A a_B(t0) = F_Q(t) p, F_Q =  int [-2 a_A a_B, 0, 0, P s, -P c] dt
// The unknown start values are nuisance intercepts, removed by centering each
// row type over the window. Only differences of E and a_A a_B enter the left
// side, and the regressors are integrals (trapezoid rule), so no noisy sample
// is ever differentiated. With white noise of std sigma on a_A and a_B, the E/2
// row carries noise a_A sigma and the Q row a_A sigma, so both are divided by
// the window's mean amplitude: the accumulated matrix is then the Fisher
// information times sigma^2 (see NormalEquations::cramer_rao_bound).
//
// A known change of the whole damping with temperature or amplitude
// (WaveSample::damping_scale k) enters the damping columns as k E, k P c4,
// k P s4 and k a_A a_B, so the parameters are those of the reference state
// and a common-damping change between windows is not taken for anisotropy.
//
// Rows are formed on blocks of `block_samples` consecutive samples (block
// means), which cuts the cost of the rank-one updates by that factor and loses
// a fraction (block/window)^2 of the information.
//
// Transient rule. An output of the demodulator depends on the pickoff samples
// of its low-pass span: the sinc^5 decimator of dsp/demodulator.hpp has 5L - 4
// taps, 4.96 ms for L = 100 at 100 kHz, i.e. the first 5 control-rate outputs
// after the switch still hold samples taken with the drive on; the DAC adds up
// to one block of latency before the drive is really off. Samples with
// t_s < t_switch_s + settle_s are therefore ignored, with
//   settle_s >= (5L - 4)/f_adc + DAC latency + one control period  (~7 ms).
// The default 20 ms is about three times that, and costs 0.4 % of a 5 s window.
//
// Context: task level at the control rate; no heap, no exceptions.

#include <estimator/types.hpp>

namespace hrg::est {

// What a finished window adds to the normal equations.
struct WindowContribution {
  AugmentedMatrix info = AugmentedMatrix::Zero();  // centered, scaled [H'H H'y; y'H y'y]
  double rows{0};                                  // number of block rows (two per block)
  double intercepts{0};                            // nuisance intercepts removed (two per window)
  double t_end_s{0};                               // time of the last settled sample
  double duration_s{0};                            // settled span used
  double mean_E_v2{0};                             // window mean of E, the row weight
  double mean_theta_rad{0};
  CoverageHistogram coverage_s{};  // settled seconds per 4theta bin
};

class WindowAccumulator {
 public:
  struct Config {
    double settle_s = 0.020;          // ignore samples this long after the switch
    int block_samples = 10;           // samples per row (block mean)
    int min_blocks = 5;               // shorter windows are dropped
    double max_sample_gap_s = 0.005;  // a larger step in t_s aborts the window
  };

  WindowAccumulator() = default;
  explicit WindowAccumulator(const Config& config) : config_(config) {}

  // Opens a window at the switch time t_switch_s (drive off). Status::in_window
  // if one is already open (the old one is kept).
  Status begin_window(double t_switch_s);
  // Feeds one control-rate sample. Samples inside the settle time return
  // Status::settling and are ignored; a gap or a bad sample aborts the window.
  Status add_sample(const WaveSample& s);
  // Closes the window; on Status::ok `out` holds its contribution.
  Status end_window(WindowContribution& out);
  // Drops the open window (e.g. the firmware aborted the free decay).
  void abort_window() { open_ = false; }

  bool window_open() const { return open_; }
  int blocks() const { return blocks_; }
  int settling_samples_rejected() const { return settling_rejected_; }
  const Config& config() const { return config_; }

 private:
  using Row4 = Eigen::Matrix<double, 4, 1>;
  using Sum4 = Eigen::Matrix<double, 4, 4>;
  void close_block();

  Config config_{};
  bool open_{false};
  bool have_first_{false};
  double t_switch_s_{0};
  double t_first_s_{0};
  double t_prev_s_{0};
  double t_block_start_s_{0};
  double E_ref_{0};
  double u_ref_{0};
  Eigen::Vector3d hE_prev_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d hQ_prev_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d FE_ = Eigen::Vector3d::Zero();  // columns nu, dnu_C, dnu_S
  Eigen::Vector3d FQ_ = Eigen::Vector3d::Zero();  // columns nu, dw_C, dw_S
  Row4 zE_block_ = Row4::Zero();
  Row4 zQ_block_ = Row4::Zero();
  double E_block_{0};
  double c4_block_{0};
  double s4_block_{0};
  int in_block_{0};
  Sum4 SE_ = Sum4::Zero();
  Sum4 SQ_ = Sum4::Zero();
  Row4 sE_ = Row4::Zero();
  Row4 sQ_ = Row4::Zero();
  double E_sum_{0};
  double c4_sum_{0};
  double s4_sum_{0};
  int blocks_{0};
  int settling_rejected_{0};
  CoverageHistogram coverage_s_{};
};

// Bin of the coverage histogram for a pattern angle (4theta folded to [0, 2pi)).
int coverage_bin(double theta_A_rad);

}  // namespace hrg::est
