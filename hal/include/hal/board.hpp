// SPDX-License-Identifier: MIT
#pragma once

#include "hal/can.hpp"
#include "hal/clock.hpp"
#include "hal/converters.hpp"
#include "hal/gpio.hpp"
#include "hal/temperature.hpp"

namespace hrg::hal {

// Everything the firmware may touch. A target (sim_target or hal_linux) defines
// board(); which one is decided when the program is linked.
struct Board {
  Adc& adc;
  Dac& dac;
  DigitalOut& excitation_enable;
  DigitalIn& fault_input;
  CanBus& can;
  MonotonicClock& clock;
  TemperatureSensor& temperature;  // NoTemperatureSensor when the board has none
};

Board& board();

}  // namespace hrg::hal
