// SPDX-License-Identifier: MIT
#include "firmware/fault_monitor.hpp"

namespace hrg::fw {

namespace {
uint32_t bump(uint32_t& counter, bool condition) {
  counter = condition ? counter + 1 : 0;
  return counter;
}
}  // namespace

uint16_t FaultMonitor::update(const MonitorInputs& in, Mode mode) {
  uint16_t bits = 0;
  const bool rung_up = mode == Mode::lock || mode == Mode::operate || mode == Mode::free_decay ||
                       mode == Mode::recover;
  // Lock is demanded only where the loops are supposed to hold it: in
  // free_decay the drives are off by design and the PLL may coast.
  const bool lock_required = mode == Mode::operate;
  if (bump(unlocked_, lock_required && !in.pll_locked) >= cfg_.lock_loss_frames) {
    bits |= fault_bit(Fault::loss_of_lock);
  }
  if (rung_up && in.amplitude_v < cfg_.collapse_fraction * cfg_.amplitude_set_v) {
    bits |= fault_bit(Fault::amplitude_collapse);
  }
  const double clipped_share = static_cast<double>(in.adc_clipped) /
                               static_cast<double>(in.adc_samples ? in.adc_samples : 1);
  if (bump(saturated_, clipped_share > cfg_.saturation_fraction) >= cfg_.saturation_frames) {
    bits |= fault_bit(Fault::adc_saturation);
  }
  if (bump(stuck_, in.adc_stuck) >= cfg_.stuck_frames) bits |= fault_bit(Fault::adc_stuck);
  if (in.recent_overruns >= cfg_.storm_overruns) bits |= fault_bit(Fault::overrun_storm);
  if (in.external_fault) bits |= fault_bit(Fault::external);
  if (in.dac_error) bits |= fault_bit(Fault::dac_fault);
  return bits;
}

bool adc_block_stuck(std::span<const hal::q31_t> frames, std::size_t channels) {
  if (channels == 0 || frames.size() < 2 * channels) return false;
  for (std::size_t c = 0; c < channels; ++c) {
    const hal::q31_t first = frames[c];
    bool same = true;
    for (std::size_t i = c + channels; i < frames.size(); i += channels) {
      if (frames[i] != first) {
        same = false;
        break;
      }
    }
    if (same) return true;
  }
  return false;
}

}  // namespace hrg::fw
