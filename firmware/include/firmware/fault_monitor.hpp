// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/mode.hpp"
#include "hal/converters.hpp"

namespace hrg::fw {

// What the monitors look at, once per base frame.
struct MonitorInputs {
  double amplitude_v = 0.0;      // a_A of the standing wave
  bool pll_locked = false;       // the chain's lock detector
  uint32_t adc_clipped = 0;      // samples at a rail in this block (all channels)
  uint32_t adc_samples = 1;      // samples in this block (all channels)
  bool adc_stuck = false;        // a channel did not change over the whole block
  uint32_t recent_overruns = 0;  // executive: frames with an overrun among the last 64
  bool external_fault = false;   // board fault input
  bool dac_error = false;        // the DAC refused a block (fatal status)
};

struct MonitorConfig {
  double amplitude_set_v = 1.0;       // AGC set point
  double collapse_fraction = 0.3;     // amplitude below this fraction of the set point collapses
  uint32_t lock_loss_frames = 50;     // consecutive frames unlocked in operate/recover
  double saturation_fraction = 0.01;  // clipped share of a block that counts as saturated
  uint32_t saturation_frames = 5;     // consecutive saturated blocks
  uint32_t stuck_frames = 10;         // consecutive stuck blocks
  uint32_t storm_overruns = 16;       // overrun frames out of the last 64
};

// Debounced fault detectors. Each returns its Fault bit while the condition
// holds for its frame count; which detectors apply depends on the mode (lock
// is only demanded once the loops have settled, amplitude only once rung up).
class FaultMonitor {
 public:
  explicit FaultMonitor(const MonitorConfig& cfg = {}) : cfg_(cfg) {}

  // Returns the fault bits active after this frame. Task context.
  uint16_t update(const MonitorInputs& in, Mode mode);

  const MonitorConfig& config() const { return cfg_; }
  void set_amplitude_set_v(double v) { cfg_.amplitude_set_v = v; }

 private:
  MonitorConfig cfg_;
  uint32_t unlocked_ = 0;
  uint32_t saturated_ = 0;
  uint32_t stuck_ = 0;
};

// True when some ADC channel holds one value over the whole interleaved block
// (a stuck converter or a broken pickoff wire). Allocation-free, one pass.
bool adc_block_stuck(std::span<const hal::q31_t> frames, std::size_t channels);

}  // namespace hrg::fw
