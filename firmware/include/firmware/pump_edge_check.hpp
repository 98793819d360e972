// SPDX-License-Identifier: MIT
#pragma once

// Do no harm for what acts only while the pump runs (a drive feedthrough left
// in the corrected signal, or added to it by a wrong correction). The
// resonator's state is continuous across the instant the excitation goes
// off; an electronics term proportional to the pump is not. At every
// switch-off the corrected quadratures X = cx - i sx, Y = cy - i sy are
// referred to a fixed frame (the NCO's phase at the last pump-on row's
// centre, advanced at its frequency then: the PLL's answer to a step does
// not turn the frame) and fitted on each side (the last pump-on rows with
// the bend the pump's own V^2 puts in the vibration, fw::PumpOnFit; a line
// through the rows after the demodulator is free of the drive), and both
// fits are taken to the switch instant. Their difference is -r P, r the residual
// feedthrough per volt of pump and P the pump envelope the pump-on rows saw
// (ChainOutputs::pump_seen_v at the pump's phase against the NCO), weighted
// as the fit weights its rows at the instant (exact for a pump that varies,
// as the AGC's does): r = -dX / P per channel, averaged over the edges seen
// since the correction last changed (weights from the fits' own residual
// noise, times the rows' correlation).
//
// The step this leaves while the pump runs, |r| V0 (the larger channel),
// turns the pattern angle read at amplitude a by up to |r| V0 / (2 a): it is
// tolerated up to max_readout_step_rad of readout (tolerance_v = 2 a sin of
// it). V0 is the largest pump envelope of the edges seen: the AGC's pump
// moves between its limits, and a feedthrough read at an edge near zero pump
// acts in full at the largest. Verdict: `step` when the step exceeds the
// tolerance by n_sigma of its noise, `consistent` when it stays under it by
// n_sigma, else `unknown`. No heap; a fixed amount of work per row (the fits
// once per edge).

#include <array>
#include <cstdint>

#include "firmware/chain_and_identifier.hpp"
#include "firmware/pump_on_fit.hpp"

namespace hrg::fw {

struct PumpEdgeCheckConfig {
  // Rows (chain blocks) fitted on each side of an edge; at most kMaxFitRows.
  uint32_t fit_rows = 64;
  // Rows after the first pump-off row until a row is free of the drive
  // (fw::app::drive_free_blocks).
  uint32_t drive_free_rows = 7;
  // The switch instant, in rows after the last row the chain ran with the
  // pump on: the last pump word ends dac_lead_frames + L - 1/2 frames after
  // that block's start; a row is centred N (L - 1)/2 frames before its last
  // sample (fw::app::pump_edge_offset_rows).
  double edge_offset_rows = 3.505;
  // A row's centre, in blocks before the end of its block (1 + N (L - 1)/2
  // frames over L; 2.485 at the default 100-frame blocks), where its NCO
  // phase is taken; at most 3.
  double row_centre_blocks = 2.485;
  // Readout error a step may cause while the pump runs (rad); 0.005 deg.
  double max_readout_step_rad = 8.726646259971648e-5;
  double n_sigma = 3.0;
  // The rows' noise is the demodulator's: successive rows share input
  // samples, so a line through them varies more than through independent
  // rows by this factor (variance; dsp::decimator_row_noise_correlation,
  // 2.3233 at the default 100-frame blocks; at 1 an edge's sigma is 1.52x
  // too small).
  double row_noise_correlation = 2.3233;
};

enum class PumpEdgeVerdict : uint8_t {
  unknown,     // no edge measured yet, or the step is within n_sigma of the tolerance
  consistent,  // the step is below the tolerance (by n_sigma)
  step,        // the step is above the tolerance (by n_sigma): the pump-on signal is wrong
};
const char* to_string(PumpEdgeVerdict v);

struct PumpEdgeStatus {
  PumpEdgeVerdict verdict = PumpEdgeVerdict::unknown;
  uint32_t edges = 0;  // switch-offs measured since the last reset
  // Residual feedthrough per volt of pump (V/V, complex), and its sigma per part.
  double x_re = 0.0;
  double x_im = 0.0;
  double y_re = 0.0;
  double y_im = 0.0;
  double sigma_v_per_v = 0.0;
  // The same sigma as the edges' own scatter gives it (the weighted spread of
  // the edges' r about their mean, pooled over the 4 parts, over edges - 1;
  // 0 below 2 edges): far above sigma_v_per_v, the edges disagree more than
  // their noise says.
  double scatter_v_per_v = 0.0;
  // How long the correction the edges were read through has been in force:
  // from the first row after the last reset to the last row (s).
  double in_force_s = 0.0;
  // At the largest pump of the edges and the last edge's amplitude: the
  // step, its sigma, the tolerance (V).
  double step_v = 0.0;
  double step_sigma_v = 0.0;
  double tolerance_v = 0.0;
};

class PumpEdgeCheck {
 public:
  static constexpr uint32_t kMaxFitRows = 64;
  // The bend's 4 coefficients are kept when they take out of the pump-on
  // rows' misfit more than F(4, 4 (n - 3)) at 0.1 % (4.7 at n = 64) times the
  // rows' correlation says chance would.
  static constexpr double kBendF = 4.7;

  explicit PumpEdgeCheck(const PumpEdgeCheckConfig& cfg);
  // The correction of the pickoffs changed: what was seen before is forgotten.
  void reset();
  // Once per chain block. `pump_on`: the chain ran this block with the pump
  // on; `steady`: the loops hold the wave (operation), so the pump-on side
  // is a line (a pump-on row that is not steady, ring-up or re-acquisition,
  // starts the pump-on side again).
  void add_row(const ChainRecord& r, bool pump_on, bool steady = true);
  const PumpEdgeStatus& status() const { return status_; }

 private:
  // Sums of a line fit of the 4 quadratures against the row index t.
  struct LineSums {
    double n = 0.0, t = 0.0, tt = 0.0;
    std::array<double, 4> y{}, ty{}, yy{};
    void add(double t_row, const std::array<double, 4>& q);
  };
  // Value at t_e of each quadrature, the extrapolation's variance factor
  // and the residual sum of squares (4 components pooled).
  struct LineAt {
    std::array<double, 4> v{};
    double var_factor = 0.0;
    double rss = 0.0;
  };
  static LineAt line_at(const LineSums& s, double t_e);
  // The NCO phase at the centre of the row just added (2^-32 cycles).
  uint32_t centre_phase(uint32_t nco_phase_end);
  // The row's quadratures in the edge's fixed frame.
  std::array<double, 4> in_frame(const std::array<double, 4>& q, uint32_t centre, double t) const;
  void begin_edge();
  void finish_edge();
  // r of this edge through one pump-on fit, and that fit's misfit without it.
  struct Reading {
    std::array<double, 4> r{};
    double p2 = 0.0;
    double pre_rss = 0.0;
  };
  static Reading read(const PumpOnFit::Result& pre, const LineAt& post);
  void decide();
  // The mean's sigma from the edges' scatter (PumpEdgeStatus::scatter_v_per_v).
  double scatter() const;

  PumpEdgeCheckConfig cfg_;
  PumpEdgeStatus status_{};
  std::array<std::array<double, 4>, kMaxFitRows> ring_{};  // the last pump-on rows
  std::array<uint32_t, kMaxFitRows> ring_phase_{};         // their centre NCO phases
  // The pump they saw: amplitude (V), phase against the NCO (rad).
  std::array<std::array<double, 2>, kMaxFitRows> ring_pump_{};
  std::array<uint32_t, 4> end_phase_{};  // the last rows' block-end phases
  uint32_t end_pos_ = 0;
  // The edge's frame: the NCO phase at the last pump-on row's centre and its
  // advance per row then.
  uint32_t frame_phase_ = 0;
  uint32_t frame_advance_ = 0;
  uint32_t ring_pos_ = 0;
  uint32_t on_rows_ = 0;  // consecutive pump-on rows (since the last reset)
  bool was_on_ = false;
  double last_amplitude_v_ = 0.0;  // of the last pump-on row
  // The edge being measured.
  bool in_edge_ = false;
  uint32_t off_rows_ = 0;  // rows since the last pump-on row
  // The pump-on side as a line, and with the pump's bend (finish_edge keeps
  // the bend where it explains the rows better than the line beyond chance).
  PumpOnFit::Result pre_line_{};
  PumpOnFit::Result pre_bend_{};
  LineSums post_{};
  double amplitude_v_ = 0.0;
  // The largest pump envelope of the edges since the last reset (V).
  double max_pump_v_ = 0.0;
  // Inverse-variance sums of r and r^2 over the edges.
  double weight_ = 0.0;
  std::array<double, 4> weighted_r_{};
  std::array<double, 4> weighted_rr_{};
  // Time of the first row since the last reset.
  double since_s_ = 0.0;
  bool since_set_ = false;
};

}  // namespace hrg::fw
