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

#include <cmath>
#include <cstdint>

#include "hal/converters.hpp"
#include "sim_target/sim_config.hpp"

namespace hrg::sim {

class AdcQuantizer {
 public:
  explicit AdcQuantizer(const AdcConfig& c = {});
  // Inline: the simulated board calls it twice per sample.
  hal::q31_t convert(double v, bool& clipped) const {
    const double scaled = round_to_even(v / lsb_v_);
    int64_t code = 0;
    clipped = false;
    if (!(scaled < static_cast<double>(code_max_))) {
      code = code_max_;
      clipped = true;
    } else if (!(scaled > static_cast<double>(-code_max_ - 1))) {
      code = -code_max_ - 1;
      clipped = true;
    } else {
      code = static_cast<int64_t>(scaled);
    }
    return static_cast<hal::q31_t>(code * (int64_t{1} << (32 - bits_)));
  }
  double lsb_v() const { return lsb_v_; }
  // std::nearbyint in the default rounding mode without the library call:
  // adding and removing 1.5 2^52 rounds to the nearest integer (ties to even)
  // for |x| < 2^51; beyond that every code saturates anyway.
  static double round_to_even(double x) {
    constexpr double kMagic = 0x1.8p52;
    return std::fabs(x) < 0x1p51 ? (x + kMagic) - kMagic : x;
  }
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
  double convert(hal::q31_t word, bool& saturated) const {
    const int64_t code = static_cast<int64_t>(word) >> (32 - bits_);
    saturated = code >= code_max_ || code <= -code_max_ - 1;
    // code / 2^(bits-1) is exact, so one product by volts_per_code_ rounds as
    // code / 2^(bits-1) * FS did.
    return static_cast<double>(code) * volts_per_code_;
  }
  // The Q1.31 word whose output is closest to v (tests, envelope helpers).
  hal::q31_t word_for(double v) const;

 private:
  uint32_t bits_;
  double full_scale_v_;
  int64_t code_max_;
  double volts_per_code_;  // FS / 2^(bits-1)
};

}  // namespace hrg::sim
