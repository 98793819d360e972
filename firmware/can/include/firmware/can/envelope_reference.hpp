// SPDX-License-Identifier: MIT
#pragma once

// Turns the chain's demodulated quadratures into the rows of an
// hrg-recording (docs/recording-format.md), so that a decoded CAN log is
// audit-grade:
//   - against a fixed reference: the chain demodulates against its NCO, whose
//     phase the PLL moves every block (about 2e-3 rad of wander at 500 Hz that
//     no reader can rebuild from the PLL frequency it sees); the quadratures
//     are turned into the reference ph(t) = 2 pi f_ref t, f_ref on the grid
//     HRG_REFERENCE carries, t the row time HRG_ROW carries (on its grid too);
//   - stamped at the centre of the demodulator's window, where the envelope
//     is (kCentre blocks and a half before the block end);
//   - with the drive state as applied: a row counts as driven until the last
//     driven DAC word (its lead and the DAC's pipeline) lies before the
//     samples the demodulator averages for it.
// Freestanding, no heap; the firmware owns one and calls it once per block.

#include <cstdint>

namespace hrg::fw::can {

struct EnvelopeReferenceConfig {
  double f_ref_hz = 5000.0;  // fixed reference (the chain's centre frequency)
  double block_period_s = 1e-3;
  // Blocks from the block end back to the envelope's centre, less a half
  // (dsp::kDecimatorOrder / 2).
  uint32_t centre_blocks = 2;
  // Blocks with the excitation off before a row is free of any drive: 1 +
  // ceil((DAC lead + DAC pipeline + (N - 1)(L - 1)) / L).
  uint32_t drive_free_blocks = 7;
};

struct EnvelopeRow {
  double t_s = 0;  // on HRG_ROW.t_s's grid
  double cx_v = 0, sx_v = 0, cy_v = 0, sy_v = 0;
  bool exc = true;
};

class EnvelopeReference {
 public:
  static constexpr uint32_t kMaxCentreBlocks = 14;

  explicit EnvelopeReference(const EnvelopeReferenceConfig& cfg);

  // Once per block, after the chain: the time of the block end (first sample
  // after it), the NCO phase there (2^-32 cycles) and whether the drives were
  // on for this block.
  void after_block(double t_block_end_s, uint32_t nco_phase, bool excitation_on);
  // Rows exist once the history reaches back to the envelope's centre.
  bool ready() const { return blocks_ >= centre_ + 2; }
  // The row of the quadratures the chain gave for the last block.
  EnvelopeRow row(double cx_v, double sx_v, double cy_v, double sy_v) const;
  // The reference as sent (on HRG_REFERENCE.f_ref_hz's grid).
  double f_ref_hz() const { return f_ref_hz_; }

 private:
  double f_ref_hz_;
  double block_period_s_;
  uint32_t centre_;
  uint32_t drive_free_blocks_;
  uint32_t off_blocks_ = 0;
  uint64_t blocks_ = 0;
  // Per block end, newest first: NCO phase minus the reference's (rad,
  // (-pi, pi]) and the time.
  double offset_rad_[kMaxCentreBlocks + 2] = {};
  double t_s_[kMaxCentreBlocks + 2] = {};
};

}  // namespace hrg::fw::can
