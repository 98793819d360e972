// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "dsp/demodulator.hpp"

namespace hrg::test {

// The demodulator's low-pass as one FIR, built independently of the chain:
// the cascade of dsp::kDecimatorOrder boxcars of block_frames samples each,
// i.e. boxcar_L^N, unnormalised (every tap an integer count).
inline std::vector<double> decimator_taps(uint32_t block_frames) {
  std::vector<double> h{1.0};
  for (uint32_t n = 0; n < dsp::kDecimatorOrder; ++n) {
    std::vector<double> next(h.size() + block_frames - 1, 0.0);
    for (std::size_t i = 0; i < h.size(); ++i)
      for (uint32_t j = 0; j < block_frames; ++j)
        next[i + j] += h[i];
    h = next;
  }
  return h;
}

}  // namespace hrg::test
