// SPDX-License-Identifier: MIT
#pragma once

// Quantisers of the simulated converters. Pure functions of their config;
// noise, offset, faults and timing are added by the simulated board.
//
// ADC: v -> code = round(v / FS * 2^(bits-1)), saturated to the code range
// [-2^(bits-1), 2^(bits-1) - 1] (a saturated sample is reported as clipped),
// then left-justified into Q1.31 (code << (32 - bits)).
// DAC: Q1.31 -> code = word >> (32 - bits) (truncation, as a DAC ignores the
// low bits) -> v = code / 2^(bits-1) * FS. A code at either rail is reported
// as saturated: the firmware asked for the converter's limit.

#include <cstdint>

#include "hal/converters.hpp"
#include "sim_target/sim_config.hpp"

namespace hrg::sim {

class AdcQuantizer {
 public:
  explicit AdcQuantizer(const AdcConfig& c = {});
  hal::q31_t convert(double v, bool& clipped) const;
  double lsb_v() const { return lsb_v_; }
  // Volts of a Q1.31 word (for tests and the back door).
  double to_volts(hal::q31_t word) const;

 private:
  uint32_t bits_;
  double full_scale_v_;
  double lsb_v_;
  int64_t code_max_;
};

class DacQuantizer {
 public:
  explicit DacQuantizer(const DacConfig& c = {});
  double convert(hal::q31_t word, bool& saturated) const;
  // The Q1.31 word whose output is closest to v (tests, envelope helpers).
  hal::q31_t word_for(double v) const;

 private:
  uint32_t bits_;
  double full_scale_v_;
  int64_t code_max_;
};

}  // namespace hrg::sim
