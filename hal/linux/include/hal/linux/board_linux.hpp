// SPDX-License-Identifier: MIT
#pragma once

#include "hal/board.hpp"
#include "hal/linux/stream_converters.hpp"

namespace hrg::hal::linux_board {

// The Linux board behind hrg::hal::board() when a program links
// hrg_board_linux (instead of hrg_board_sim). Devices are opened on the first
// call to board(), from the environment:
//   HRG_CAN_IF            CAN interface                  (can0)
//   HRG_GPIO_CHIP         chip of the two lines          (gpiochip0)
//   HRG_EXC_LINE          excitation enable line offset  (0)
//   HRG_EXC_ACTIVE_LOW    1: the enable is active low    (0)
//   HRG_FAULT_LINE        fault input line offset        (1)
//   HRG_ADC_DEV, HRG_DAC_DEV        sample streams (/dev/iio:device0, /dev/iio:device1)
//   HRG_ADC_FORMAT, HRG_DAC_FORMAT  IIO scan element types (le:s16/16>>0)
//   HRG_ADC_FULL_SCALE_V, HRG_DAC_FULL_SCALE_V  volts at Q1.31 full scale (2.5, 10)
//   HRG_SAMPLE_RATE_HZ    converter rate                 (100000)
//   HRG_BLOCK_FRAMES      frames per block               (100)
//   HRG_TEMP_PATH         resonator temperature, a file of millidegrees C
//                         (IIO in_temp*_input, hwmon temp*_input); unset: no
//                         sensor (the temperature input reads `closed`)
// A device that does not open leaves its object closed: every call on it
// returns Status::closed, and board_open_status() says which and why.
struct BoardOpenStatus {
  Status can = Status::closed;
  Status excitation = Status::closed;
  Status fault = Status::closed;
  Status adc = Status::closed;
  Status dac = Status::closed;
  Status temperature = Status::closed;
  const char* temperature_error = "";  // why the temperature file was refused (path named)
};
BoardOpenStatus board_open_status();

}  // namespace hrg::hal::linux_board
