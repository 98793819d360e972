// SPDX-License-Identifier: MIT
#pragma once

#include "hal/status.hpp"

namespace hrg::hal {

// One digital output line, e.g. the excitation enable that gates the drive
// amplifiers in hardware (a second, independent path to "drives off").
class DigitalOut : NonCopyable {
 public:
  virtual ~DigitalOut() = default;
  virtual Status write(bool active) = 0;
};

// One digital input line, e.g. the board's fault input (amplifier over-current).
class DigitalIn : NonCopyable {
 public:
  virtual ~DigitalIn() = default;
  virtual Status read(bool& active) = 0;
};

}  // namespace hrg::hal
