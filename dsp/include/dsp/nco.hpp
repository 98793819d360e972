// SPDX-License-Identifier: MIT
#pragma once

// Numerically controlled oscillator: a wrapping uint32_t phase (2^32 = one
// turn) and a sine table with linear interpolation, for float, double and
// Q1.31 from one table definition.
//
// Error bound of sine/cosine (all types): |error| <= 4.8e-6 of full scale,
// i.e. (2 pi / 1024)^2 / 8 = 4.71e-6 from linear interpolation over 1024
// segments, plus 2^-31 table rounding and 2^-31 interpolation rounding for
// Q1.31 (float adds its own ~6e-8). The test checks the bound over 2^20
// phases for every type.

#include <array>
#include <numbers>
#include <cstddef>
#include <cstdint>

#include "dsp/fixed.hpp"
#include "dsp/sample.hpp"

namespace hrg::dsp {

namespace detail {

inline constexpr double kPi = std::numbers::pi;

// sin(x) for 0 <= x <= pi/2 by its Taylor series (27th order: error below
// 1e-17 at pi/2); evaluated by the compiler, so host and target tables match.
constexpr double sin_taylor(double x) {
  double term = x;
  double sum = x;
  for (int k = 1; k < 14; ++k) {
    term *= -x * x / static_cast<double>((2 * k) * (2 * k + 1));
    sum += term;
  }
  return sum;
}

// sin(2 pi i / n) with exact quarter-wave symmetry (n divisible by 4).
constexpr double sin_of_index(std::size_t i, std::size_t n) {
  const std::size_t q = n / 4;
  i %= n;
  const std::size_t quadrant = i / q;
  const std::size_t j = i % q;
  const double step = 2.0 * kPi / static_cast<double>(n);
  switch (quadrant) {
    case 0: return sin_taylor(static_cast<double>(j) * step);
    case 1: return sin_taylor(static_cast<double>(q - j) * step);
    case 2: return -sin_taylor(static_cast<double>(j) * step);
    default: return -sin_taylor(static_cast<double>(q - j) * step);
  }
}

}  // namespace detail

inline constexpr int kSineTableBits = 10;
inline constexpr std::size_t kSineTableSize = std::size_t{1} << kSineTableBits;
inline constexpr int kSineFracBits = 32 - kSineTableBits;

template <typename T>
constexpr T sine_table_entry(std::size_t i) {
  if constexpr (SampleOps<T>::kFixed) {
    // -1.0 is clamped to -(1 - 2^-31): the table is symmetric and a product
    // with any Q1.31 sample stays below 1.0 in magnitude.
    const q31_t v = q31_from_f64_sat(detail::sin_of_index(i, kSineTableSize));
    return v == kQ31Min ? -kQ31Max : v;
  } else {
    return static_cast<T>(detail::sin_of_index(i, kSineTableSize));
  }
}

// One full period plus a guard entry so index + 1 never wraps.
template <typename T>
struct SineTable {
  static constexpr std::array<T, kSineTableSize + 1> make() {
    std::array<T, kSineTableSize + 1> t{};
    for (std::size_t i = 0; i <= kSineTableSize; ++i)
      t[i] = sine_table_entry<T>(i);
    return t;
  }
  static constexpr std::array<T, kSineTableSize + 1> kValues = make();
};

// sin(2 pi phase / 2^32).
// Input: any uint32_t phase (wraps by construction).
// Output: Q1.31 in [-(2^31 - 1), 2^31 - 1] (never the -1.0 rail, so its
// product with any Q1.31 sample fits Q1.31 units after the 31-bit shift), or
// float/double in [-1, 1].
// Rounding (Q1.31): interpolation to nearest, ties toward +inf. Overflow: none
// (the result lies between two table entries).
template <typename T>
HRG_DSP_INLINE T sin_turns(uint32_t phase) {
  const auto& t = SineTable<T>::kValues;
  const uint32_t i = phase >> kSineFracBits;
  const uint32_t frac = phase & ((uint32_t{1} << kSineFracBits) - 1u);
  const T a = t[i];
  const T b = t[i + 1];
  if constexpr (SampleOps<T>::kFixed) {
    const q63_t d = static_cast<q63_t>(b) - a;  // |d| < 2^24
    return static_cast<T>(a + rshift_q63_rnd(d * static_cast<q63_t>(frac), kSineFracBits));
  } else {
    constexpr T kScale = T(1) / static_cast<T>(uint32_t{1} << kSineFracBits);
    return a + (b - a) * (static_cast<T>(frac) * kScale);
  }
}

// cos(2 pi phase / 2^32), same contract as sin_turns.
template <typename T>
HRG_DSP_INLINE T cos_turns(uint32_t phase) {
  return sin_turns<T>(phase + (uint32_t{1} << 30));
}

// Phase increment per sample for frequency f_hz at sample rate fs_hz.
// Rounding: to nearest. Frequencies outside [0, fs) wrap (aliasing), which is
// what the wrapping accumulator does with them anyway.
inline uint32_t phase_step_of_hz(double f_hz, double fs_hz) {
  double turns = f_hz / fs_hz;
  turns -= static_cast<double>(static_cast<int64_t>(turns));
  if (turns < 0.0) turns += 1.0;
  return static_cast<uint32_t>(static_cast<uint64_t>(turns * 4294967296.0 + 0.5));
}

// Frequency of a phase increment, Hz.
inline double hz_of_phase_step(uint32_t step, double fs_hz) {
  return static_cast<double>(step) * fs_hz / 4294967296.0;
}

// Angle in radians -> phase offset (turns * 2^32), wrapping. Rounding: to nearest.
inline uint32_t phase_of_rad(double rad) {
  double turns = rad / (2.0 * detail::kPi);
  turns -= static_cast<double>(static_cast<int64_t>(turns));
  if (turns < 0.0) turns += 1.0;
  return static_cast<uint32_t>(static_cast<uint64_t>(turns * 4294967296.0 + 0.5));
}

// The oscillator itself. Phase and increment are plain integers: the phase
// wraps modulo 2^32 (one turn) and never loses precision however long it runs.
class Nco {
 public:
  void set_step(uint32_t step) { step_ = step; }
  uint32_t step() const { return step_; }
  void set_phase(uint32_t phase) { phase_ = phase; }
  uint32_t phase() const { return phase_; }
  // Advances by n samples (wrapping) and returns the phase before the advance.
  uint32_t advance(uint32_t n) {
    const uint32_t p = phase_;
    phase_ += step_ * n;
    return p;
  }

 private:
  uint32_t phase_ = 0;
  uint32_t step_ = 0;
};

}  // namespace hrg::dsp
