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
#include <cstddef>
#include <cstdint>

#include "hal/converters.hpp"
#include "sim_target/sim_config.hpp"

namespace hrg::sim {

class AdcQuantizer {
 public:
  explicit AdcQuantizer(const AdcConfig& c = {});
  // Inline: the simulated board calls it twice per sample.
  hal::q31_t convert(double v, bool& clipped) const {
    const int64_t code = code_of(scaled(v));
    clipped = code == code_max_ || code == -code_max_ - 1;
    return static_cast<hal::q31_t>(code * (int64_t{1} << (32 - bits_)));
  }
  // round(v / lsb) with ties to even, as a double: the product with 1/lsb
  // instead of the division, with the division's bits. Why it is exact: for
  // |v / lsb| < 2^32, s = fl(v fl(1/lsb)) is within 2u|v/lsb| (1 + u) < 2^-20
  // of v / lsb and fl(v / lsb) within u|v/lsb| < 2^-21 of it (u = 2^-53).
  // When s is at least 2^-19 from every half-integer h, v / lsb and the
  // division's result lie on s's side of h and differ from it, so both
  // round to the same integer; nearer than that (about one sample in 2^18)
  // the division is done. Beyond 2^32 both clip, with the same sign.
  double scaled(double v) const {
    const double s = v * inv_lsb_;
    const double r = round_to_even(s);
    if (std::fabs(std::fabs(s - r) - 0.5) < kTieGuard || !inverse_exact_)
      return round_to_even(v / lsb_v_);
    return r;
  }
  // n conversions of v into out with convert()'s words; returns how many
  // clipped. A tight loop without a branch per sample: the product is
  // clamped to one code beyond each rail first (every decision convert()
  // makes is kept: beyond a rail is beyond it), so that the 1.5 2^52
  // rounding holds, and a block with a near-tie anywhere is done again by
  // convert() (see scaled()).
  uint32_t convert_block(const double* v, hal::q31_t* out, std::size_t n) const {
    constexpr double kMagic = 0x1.8p52;
    const double hi = static_cast<double>(code_max_);
    const double lo = -hi - 1.0;
    const uint32_t shift = 32 - bits_;
    uint32_t clipped = 0;
    bool near_tie = !inverse_exact_;
    for (std::size_t i = 0; i < n; ++i) {
      double s = v[i] * inv_lsb_;
      s = s < hi + 1.0 ? s : hi + 1.0;  // NaN goes high, as in code_of()
      s = s > lo - 1.0 ? s : lo - 1.0;
      const double r = (s + kMagic) - kMagic;
      near_tie |= std::fabs(s - r) > 0.5 - kTieGuard;
      const double c = r < hi ? (r > lo ? r : lo) : hi;
      clipped += (r >= hi || r <= lo) ? 1u : 0u;
      out[i] = static_cast<hal::q31_t>(static_cast<uint32_t>(static_cast<int32_t>(c)) << shift);
    }
    if (!near_tie) return clipped;
    clipped = 0;
    for (std::size_t i = 0; i < n; ++i) {
      bool clip = false;
      out[i] = convert(v[i], clip);
      clipped += clip ? 1u : 0u;
    }
    return clipped;
  }
  // The saturated code of a rounded value (NaN saturates high, as it always has).
  int64_t code_of(double rounded) const {
    if (!(rounded < static_cast<double>(code_max_))) return code_max_;
    if (!(rounded > static_cast<double>(-code_max_ - 1))) return -code_max_ - 1;
    return static_cast<int64_t>(rounded);
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
  double inv_lsb_;      // 1 / lsb_v_, rounded
  bool inverse_exact_;  // both normal numbers: the argument in scaled() holds
  int64_t code_max_;
  static constexpr double kTieGuard = 0x1p-19;
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
