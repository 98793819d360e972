// SPDX-License-Identifier: MIT
#pragma once

#include "firmware/gyro.hpp"

namespace hrg::test {

// A gyro configuration for the fake chain and board: free-decay windows of
// 200 frames every 300, in 16 bins, on a base that never turns, so that a
// few thousand lockstep frames carry the firmware through acquisition,
// windows and solves (the allocation test and the model check's cost).
inline fw::GyroConfig short_window_config() {
  fw::GyroConfig c;
  c.settle_frames = 20;
  c.windows.length_frames = 200;
  c.windows.period_frames = 300;
  c.windows.bins = 16;
  c.windows.windows_per_bin = 100;
  c.windows.max_wait_frames = 300;
  c.windows.rotate_on_static_base = false;
  return c;
}

}  // namespace hrg::test
