// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

#include "firmware/estimator_health.hpp"
#include "firmware/mode.hpp"
#include "firmware/window_scheduler.hpp"

namespace hrg::test {

// A minimal mode machine around a window scheduler: operate <-> free_decay,
// one frame per call. Counts the windows opened and where the last one began.
struct WindowLoop {
  fw::WindowScheduler s;
  fw::Mode mode = fw::Mode::operate;
  uint32_t opened = 0;
  uint64_t last_open_frame = 0;  // scheduler frame count at the last window's start
  explicit WindowLoop(const fw::WindowConfig& c) : s(c) {}
  fw::WindowDecision frame(double theta, double rate, const fw::EstimatorHealth& h = {}) {
    const fw::WindowDecision d = s.step(mode, theta, rate, h);
    if (d.open) {
      mode = fw::Mode::free_decay;
      ++opened;
      last_open_frame = s.frames();
    }
    if (d.close) mode = fw::Mode::operate;
    return d;
  }
};

}  // namespace hrg::test
