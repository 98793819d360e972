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
#include <cstring>

#include "hal/converters.hpp"
#include "sim_target/sim_config.hpp"

namespace hrg::sim {

// SIMD vectors of kLanes doubles, 64-bit masks and 32-bit words (GCC's
// vector extensions; a size that depends on a template parameter needs a
// specialisation per size).
template <std::size_t kLanes>
struct Lanes;
template <>
struct Lanes<2> {
  using d = double __attribute__((vector_size(16)));
  using l = int64_t __attribute__((vector_size(16)));
  using i = int32_t __attribute__((vector_size(8)));
  using u = uint32_t __attribute__((vector_size(8)));
};
template <>
struct Lanes<4> {
  using d = double __attribute__((vector_size(32)));
  using l = int64_t __attribute__((vector_size(32)));
  using i = int32_t __attribute__((vector_size(16)));
  using u = uint32_t __attribute__((vector_size(16)));
};

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
  // clipped. kLanes samples at a time without a branch (two doubles are one
  // SIMD register on the baseline targets, four under AVX2; where there is
  // none the compiler splits the vectors, with the same operations per
  // sample): the product is clamped to one code beyond each rail first
  // (every decision convert() makes is kept: beyond a rail is beyond it), so
  // that the 1.5 2^52 rounding holds, and a block with a near-tie anywhere
  // is done again by convert() (see scaled()).
  uint32_t convert_block(const double* v, hal::q31_t* out, std::size_t n) const {
    return convert_lanes<2>(v, out, n);
  }
  template <std::size_t kLanes>
  [[gnu::always_inline]] uint32_t convert_lanes(const double* v, hal::q31_t* out,
                                                std::size_t n) const {
    using vd = typename Lanes<kLanes>::d;
    using vl = typename Lanes<kLanes>::l;
    using vi = typename Lanes<kLanes>::i;
    using vu = typename Lanes<kLanes>::u;
    const vd zero{};
    const vd magic = zero + 0x1.8p52;
    const vd hi = zero + static_cast<double>(code_max_);
    const vd lo = zero + (-static_cast<double>(code_max_) - 1.0);
    const vd above = hi + 1.0;
    const vd below = lo - 1.0;
    const vd inv = zero + inv_lsb_;
    const vd tie = zero + (0.5 - kTieGuard);
    const vl magnitude = (vl{} - 1) ^ (vl)(zero - 0.0);  // every bit but the sign
    const uint32_t shift = 32 - bits_;
    vl clipped{};  // minus the count per lane (a true comparison is -1)
    vl near_tie{};
    const auto lanes = [&](const vd& x) __attribute__((always_inline)) {
      vd s = x * inv;
      s = s < above ? s : above;  // NaN goes high, as in code_of()
      s = s > below ? s : below;
      const vd r = (s + magic) - magic;
      near_tie |= (vd)((vl)(s - r) & magnitude) > tie;  // |s - r|
      const vd c = r < hi ? (r > lo ? r : lo) : hi;
      clipped += (r >= hi) | (r <= lo);
      // The code's bits shifted as unsigned (convert() does the same).
      return (vi)((vu) __builtin_convertvector(c, vi) << shift);
    };
    std::size_t i = 0;
    for (; i + kLanes <= n; i += kLanes) {
      vd x;
      std::memcpy(&x, v + i, sizeof x);
      const vi w = lanes(x);
      std::memcpy(out + i, &w, sizeof w);
    }
    if (i < n) {  // the rest with 0 V in the spare lanes: it neither clips nor ties
      vd x{};
      std::memcpy(&x, v + i, (n - i) * sizeof(double));
      const vi w = lanes(x);
      std::memcpy(out + i, &w, (n - i) * sizeof(hal::q31_t));
    }
    int64_t lanes_clipped = 0;
    int64_t lanes_near_tie = 0;
    for (std::size_t l = 0; l < kLanes; ++l) {
      lanes_clipped -= clipped[l];
      lanes_near_tie |= near_tie[l];
    }
    if (inverse_exact_ && lanes_near_tie == 0) return static_cast<uint32_t>(lanes_clipped);
    uint32_t count = 0;
    for (std::size_t k = 0; k < n; ++k) {
      bool clip = false;
      out[k] = convert(v[k], clip);
      count += clip ? 1u : 0u;
    }
    return count;
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
  // n conversions of words into volts with convert()'s values; returns how
  // many saturated. In 32-bit integers (a word's code fits them), without a
  // branch, so that the compiler converts several words per instruction.
  uint32_t convert_block(const hal::q31_t* words, double* volts, std::size_t n) const {
    const auto shift = static_cast<int32_t>(32 - bits_);
    const auto hi = static_cast<int32_t>(code_max_);
    const int32_t lo = -hi - 1;
    uint32_t saturated = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const int32_t code = words[i] >> shift;
      saturated += static_cast<uint32_t>(code >= hi) | static_cast<uint32_t>(code <= lo);
      volts[i] = static_cast<double>(code) * volts_per_code_;
    }
    return saturated;
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
