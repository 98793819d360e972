// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "hal/status.hpp"

namespace hrg::hal {

// Sample words are Q1.31 fractions of the converter's full scale: INT32_MIN is
// -full scale, INT32_MAX is +full scale (less one LSB). A converter with fewer
// bits left-justifies its code, so the firmware never depends on resolution.
// The same word as dsp::q31_t (the firmware checks that they agree).
using q31_t = int32_t;

inline constexpr std::size_t kAdcChannels = 2;  // 0: pickoff x (C), 1: pickoff y (D)
inline constexpr std::size_t kDacChannels =
    3;  // 0: pump (ring electrode), 1: forcer x, 2: forcer y

struct ConverterInfo {
  uint32_t sample_rate_hz;  // samples per second per channel
  uint32_t block_frames;    // frames per block (one frame = one sample of each channel)
  double full_scale_v;      // volts at the converter pin for a Q1.31 value of 1.0
};

// Pickoff ADC. Blocks are interleaved frames: [x0, y0, x1, y1, ...].
class Adc : NonCopyable {
 public:
  virtual ~Adc() = default;
  virtual ConverterInfo info() const = 0;
  // Waits for (lockstep: produces) the next block. `frames` must hold
  // block_frames * kAdcChannels words. `t_first_ns` is the sample time of the
  // first frame on the HAL's monotonic clock. `clipped` counts samples at a rail.
  // Called from the executive's base frame only.
  virtual Status read_block(std::span<q31_t> frames, uint64_t& t_first_ns, uint32_t& clipped) = 0;
};

// Drive DAC. Blocks are interleaved frames: [pump0, fx0, fy0, pump1, ...].
class Dac : NonCopyable {
 public:
  virtual ~Dac() = default;
  virtual ConverterInfo info() const = 0;
  // Queues one block to be output one block later (the converter double-buffers).
  // `frames` must hold block_frames * kDacChannels words.
  virtual Status write_block(std::span<const q31_t> frames) = 0;
};

}  // namespace hrg::hal
