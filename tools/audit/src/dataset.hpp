// SPDX-License-Identifier: MIT
#pragma once

// The recording cut into what the fit uses: free-decay segments averaged into
// short blocks, excitation segments reduced to their mean wave frequency, and
// the switching edges. Signals are turned into a frame rotating at the
// carrier estimate so that what is left in them is slow.

#include <array>
#include <complex>
#include <string>
#include <vector>

#include "recording/recording.hpp"

namespace hrg::audit::detail {

using cplx = std::complex<double>;

struct Block {
  double t_s = 0.0;                     // mean sample time
  double m2 = 0.0, m3 = 0.0, m4 = 0.0;  // central moments of the sample times (s^k)
  double n = 0.0;                       // samples in the block
  cplx x, y;                            // mean derotated envelopes X = cx - i sx, Y = cy - i sy
  double temp_c = 0.0;
  double rate_rad_s = 0.0;
  double a2_v2 = 0.0;      // measured a_A^2
  double theta_rad = 0.0;  // measured pattern angle (continuous)
  cplx rot;                // mean derotation phasor of the block (carries a constant offset)
};

struct FreeSegment {
  std::size_t first_block = 0, n_blocks = 0;
  std::size_t first_row = 0, last_row = 0;
  double t0_s = 0.0, t1_s = 0.0;
  bool heldout = false;
};

// Mean wave frequency over one excitation segment.
// Rows averaged at each end of an excitation segment for its phase and amplitude.
inline constexpr std::size_t kEndRows = 3;

struct ForcedSegment {
  std::size_t first_row = 0, last_row = 0;
  double t0_s = 0.0, t1_s = 0.0;
  double freq_rad_s = 0.0;              // (phase_end - phase_start)/duration in the carrier frame
  double se_rad_s = 0.0;                // from the white noise at the end rows' own a_A
  double sigma_rad_s = 0.0;             // weight in the fit: se and the scatter the model leaves
  double mean_c4 = 0.0, mean_s4 = 0.0;  // mean cos/sin 4 theta
  double theta0_rad = 0.0, theta1_rad = 0.0;  // the single end rows' (the angle drift's ends)
  // The angles of the three rows at each end that freq_rad_s and dlna_per_s
  // average: a readout the pickoff map makes of the angle changes the
  // measured phase and amplitude between these ends, over t1 - t0. Between
  // the single end rows it is (q1 - q0) / (q1 - q0 - 2) as large, 2.7 % on
  // the firmware's 0.75 s segments, and the phase mismatch's readout (the
  // split's shape at one table rate) left that in the segments' frequency:
  // design 5 of `audit-bench --seed 2026` read a phase mismatch 23 % low.
  std::array<double, kEndRows> theta_start_rad{}, theta_end_rad{};
  // Mean over those end rows of change(theta at the start, theta at the end).
  template <typename F>
  double end_change(F change) const {
    double sum = 0.0;
    for (std::size_t j = 0; j < kEndRows; ++j)
      sum += change(theta_start_rad[j], theta_end_rad[j]);
    return sum / static_cast<double>(kEndRows);
  }
  double mean_v2 = 0.0;                     // mean pump_v^2
  double mean_v2c4 = 0.0, mean_v2s4 = 0.0;  // mean pump_v^2 cos/sin 4 theta
  double dlna_per_s = 0.0;  // (ln a_A(end) - ln a_A(start)) / (t1 - t0), ends as for the phase
  double balance_se_per_s = 0.0;     // of dlna_per_s, from the white noise
  double balance_sigma_per_s = 0.0;  // weight of the amplitude balance (0: not used)
  // Held by the amplitude loop among segments that recover from a window:
  // the pump's efficiency once its phase has settled is a constant of its
  // own (PumpGain), not the recovering segments' law at a_A'/a_A = 0.
  bool pump_settled = false;
  // The pattern-angle drift (theta1 - theta0) / angle_span_s: its end angles
  // are single rows, so it is read over those rows' own span (the three-row
  // means' t1 - t0 is two rows shorter and left 2 dt / T of K Omega / 2 in it).
  double angle_span_s = 0.0;
  // The input rate over that span: its integral between the end rows (the
  // trapezoid over the rows) over angle_span_s. The mean of the rows weighs
  // the two ends twice as much as the integral does; on a segment the table
  // starts or stops turning in, that alone put 0.7e-5 to 1.4e-5 rad/s of
  // K Omega / 2 into the drift.
  double angle_rate_rad_s = 0.0;
  double angle_se_rad_s = 0.0;     // of the drift, from the white noise
  double angle_sigma_rad_s = 0.0;  // weight of the pattern-angle drift (0: not used)
  // What a drive feedthrough adds to the drift, taken out of it
  // (Auditor::remove_feedthrough_pull; 0 when none is shown).
  double angle_pull_rad_s = 0.0;
  double mean_a2 = 0.0;  // mean a_A^2
  double mean_temp_c = 0.0;
  double mean_rate_rad_s = 0.0;
  // Change over the segment, per second and with the ends as for the phase,
  // of (pump_v / a_A) (cos 2 theta, sin 2 theta), theta in (-pi/4, pi/4] as
  // the pump's phase follows the wave: a drive feedthrough c (per pickoff, in
  // the frame of the wave phase) moves the measured phase by
  // Im(c_x) ft_gx + Im(c_y) ft_gy (Auditor::remove_feedthrough_pull).
  double ft_gx_per_s = 0.0, ft_gy_per_s = 0.0;
  // The same change between the single end rows over angle_span_s: the
  // feedthrough's in-phase part turns the measured theta by
  // (Re(c_y) g_x - Re(c_x) g_y) / 2, so the drift by that of these.
  double ft_ax_per_s = 0.0, ft_ay_per_s = 0.0;
  // Mean over the segment of (pump_v / a_A) e^{2 i theta} pump_v^2, V^2: the
  // pump's phase follows the measured wave, which a feedthrough turns off the
  // true one, and a pump off the wave pulls the true frequency in proportion
  // to its drive (pump_phase_pull, model.hpp).
  double ft_hx_v2 = 0.0, ft_hy_v2 = 0.0;
  // Slow noise on the demodulated signals as the segment's observations see
  // it: the change of freq_rad_s, dlna_per_s and the pattern-angle drift
  // (rows 0-2) per volt of an offset on cx, sx, cy, sy (columns 0-3) and per
  // volt of one growing in time, 1 V per second from the recording's middle
  // (columns 4-7). The slowest octaves of 1/f noise are such offsets and
  // drifts, read at the end rows (offset_shapes, noise_model.hpp).
  std::array<std::array<double, 8>, 3> per_offset{};
};

// A switching of exc between a free-decay segment and an excitation segment.
struct Edge {
  std::size_t free_segment = 0;          // index into free segments
  bool at_start = false;                 // edge at the start of the free segment (exc 1 -> 0)
  std::vector<std::size_t> forced_rows;  // nearest excitation rows, nearest first
  // Excitation rows beyond forced_rows, nearest first: the force-driven slope
  // at the edge is measured on them so that its noise is independent of the
  // jump's (a direction taken from the jump's own rows bends the jump's noise
  // towards it and biases the sign-free statistic).
  std::vector<std::size_t> slope_rows;
  double pump_v = 0.0;                // mean |pump_v| over forced_rows (1 without the column)
  std::vector<double> forced_pump_v;  // |pump_v| of each forced row (empty without the column)
  std::vector<double> slope_pump_v;   // |pump_v| of each slope row (empty without the column)
  std::size_t pump_off_rows = 0;      // excitation rows at the edge whose pump was already off
};

struct Dataset {
  std::vector<Block> blocks;
  std::vector<FreeSegment> free;
  std::vector<ForcedSegment> forced;
  std::vector<Edge> edges;
  // Per-row derotated envelopes (for the edges) and times.
  std::vector<double> t_s;
  std::vector<cplx> x, y;
  std::vector<double> frame_phase_rad;  // derotation applied at each row
  double carrier_rad_s = 0.0;           // frame frequency minus the metadata f_ref, rad/s
  double f_ref_hz = 0.0;
  double angular_gain = 0.0;
  double noise_v = 0.0;  // per-sample, per-quadrature white noise
  double temp_ref_c = 0.0;
  double t_mid_s = 0.0;  // middle of the recording: origin of the generic time terms
  bool has_temp = false, has_pump = false, has_rate = false;
  double temp_span_c = 0.0, a2_span_v2 = 0.0, rate_span_rad_s = 0.0;
  int samples_per_block = 1;
  // Excitation runs left out because their pump_v jitters from row to row
  // by more than kMaxPumpJitter of its level (excitation_segments.cpp, pump_jitter).
  std::size_t forced_jittery = 0;
  std::vector<std::string> notes;
};

Dataset build_dataset(const recording::Recording& rec, int max_blocks);

}  // namespace hrg::audit::detail
