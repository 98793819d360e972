// SPDX-License-Identifier: MIT
#pragma once

#include "hal/status.hpp"

namespace hrg::hal {

// The resonator's temperature as the board measures it (a sensor on or next
// to the resonator: an IIO or hwmon channel on a Linux board, the simulated
// target's sensor model). The firmware reads it at a low rate to refer the
// calibration's thermal model to; the value is the sensor's, with its
// resolution, noise and lag, never the resonator's true temperature.
class TemperatureSensor : NonCopyable {
 public:
  virtual ~TemperatureSensor() = default;
  // The latest conversion, degC. ok: `temp_c` is fresh; closed: the board
  // has no sensor (or it never opened); io_error: the read failed or its
  // content was not a temperature (`temp_c` unchanged).
  virtual Status read(double& temp_c) = 0;
};

// The board without a temperature input: every read is `closed`.
class NoTemperatureSensor final : public TemperatureSensor {
 public:
  Status read(double& temp_c) override {
    (void)temp_c;
    return Status::closed;
  }
};

}  // namespace hrg::hal
