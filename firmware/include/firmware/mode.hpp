// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

namespace hrg::fw {

// Operating modes of the gyro controller. Values are stable: they go on the
// CAN bus and into recordings (`mode` column).
enum class Mode : uint8_t {
  power_up = 0,    // converters start, drives at zero, self-checks
  ring_up = 1,     // excite the resonator from rest
  lock = 2,        // PLL, AGC and quadrature loops settle
  operate = 3,     // whole-angle operation, output valid
  free_decay = 4,  // excitation off for an identification window
  recover = 5,     // loops re-acquire after a window
  fault = 6,       // a fault was detected; drives held, recovery attempted
  safe = 7,        // drives at zero until commanded out
};

// Fault causes, as a bit set (CAN `faults` signal).
enum class Fault : uint16_t {
  none = 0,
  loss_of_lock = 1u << 0,
  amplitude_collapse = 1u << 1,
  adc_saturation = 1u << 2,
  adc_stuck = 1u << 3,
  overrun_storm = 1u << 4,
  dac_fault = 1u << 5,
  external = 1u << 6,  // board fault input asserted
};

constexpr uint16_t fault_bit(Fault f) { return static_cast<uint16_t>(f); }

// Default timing shared by the firmware and the simulated target.
inline constexpr uint32_t kAdcRateHz = 100'000;                     // pickoff sampling
inline constexpr uint32_t kBlockFrames = 100;                       // ADC/DAC frames per block
inline constexpr uint32_t kBaseRateHz = kAdcRateHz / kBlockFrames;  // 1 kHz base frame

}  // namespace hrg::fw
