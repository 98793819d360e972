// SPDX-License-Identifier: MIT
#include "firmware/can/envelope_reference.hpp"

#include <cmath>
#include <numbers>

#include "firmware/can/messages.hpp"

namespace hrg::fw::can {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// The value a reader decodes from a signal that was sent `v`.
double on_grid(Tm message, std::size_t signal, double v) {
  const SignalDef& s = telemetry_def(message).signals[signal];
  return std::round((v - s.offset) / s.factor) * s.factor + s.offset;
}

}  // namespace

EnvelopeReference::EnvelopeReference(const EnvelopeReferenceConfig& cfg)
    : f_ref_hz_(on_grid(Tm::reference, sig::f_ref_hz, cfg.f_ref_hz)),
      block_period_s_(cfg.block_period_s),
      centre_(cfg.centre_blocks < kMaxCentreBlocks ? cfg.centre_blocks : kMaxCentreBlocks),
      drive_free_blocks_(cfg.drive_free_blocks),
      off_blocks_(cfg.drive_free_blocks) {}

void EnvelopeReference::after_block(double t_block_end_s, uint32_t nco_phase, bool excitation_on) {
  off_blocks_ = excitation_on ? 0 : off_blocks_ + 1;
  const double nco_cycles = static_cast<double>(nco_phase) * 0x1p-32;
  const double ref_cycles = std::fmod(f_ref_hz_ * t_block_end_s, 1.0);
  for (uint32_t i = centre_ + 1; i > 0; --i) {
    offset_rad_[i] = offset_rad_[i - 1];
    t_s_[i] = t_s_[i - 1];
  }
  offset_rad_[0] = kTwoPi * std::remainder(nco_cycles - ref_cycles, 1.0);
  t_s_[0] = t_block_end_s;
  ++blocks_;
}

EnvelopeRow EnvelopeReference::row(double cx_v, double sx_v, double cy_v, double sy_v) const {
  EnvelopeRow r;
  // Half-way between the block ends around the centre: the phases of NCO
  // and reference both move linearly there.
  const double t_centre_s = 0.5 * (t_s_[centre_] + t_s_[centre_ + 1]);
  const double offset_centre =
      offset_rad_[centre_] +
      0.5 * std::remainder(offset_rad_[centre_ + 1] - offset_rad_[centre_], kTwoPi);
  // The reader rebuilds ph at the time it decodes: the rounding of the
  // time to its grid goes into the turn (the NCO's phase stays at the true time).
  r.t_s = on_grid(Tm::row, sig::row_t_s, t_centre_s);
  const double turn =
      offset_centre + kTwoPi * std::remainder(f_ref_hz_ * (t_centre_s - r.t_s), 1.0);
  // x = Re((cx - i sx) e^(i ph_nco)) = Re((cx' - i sx') e^(i ph)) with
  // cx' - i sx' = (cx - i sx) e^(i (ph_nco - ph)).
  const double c = std::cos(turn);
  const double s = std::sin(turn);
  r.cx_v = cx_v * c + sx_v * s;
  r.sx_v = sx_v * c - cx_v * s;
  r.cy_v = cy_v * c + sy_v * s;
  r.sy_v = sy_v * c - cy_v * s;
  r.exc = off_blocks_ < drive_free_blocks_;
  return r;
}

}  // namespace hrg::fw::can
