// SPDX-License-Identifier: MIT
#pragma once

// Fixed-point vocabulary and scalar helpers (CMSIS-DSP names). Every helper
// states its scaling, what it does on overflow and how it rounds. Signed
// shifts and narrowing are done through well-defined C++20 semantics
// (two's complement, arithmetic right shift), so host and Cortex-M7 give the
// same bits.

#include <cstdint>

namespace hrg::dsp {

// CMSIS-style fixed-point vocabulary. Qm.n: m integer bits (sign included), n fraction bits.
using q15_t = int16_t;  // Q1.15
using q31_t = int32_t;  // Q1.31
using q63_t = int64_t;  // Q1.63, or Q2.62 for a product of two Q1.31 values

inline constexpr q31_t kQ31Max = INT32_MAX;
inline constexpr q31_t kQ31Min = INT32_MIN;
inline constexpr double kQ31One = 2147483648.0;  // 2^31: the value 1.0 in Q1.31 units

// Q2.62 (or any q63 accumulator scaled like Q1.63 >> 32) -> Q1.31.
// Overflow: saturates to [INT32_MIN, INT32_MAX]. Rounding: none (the caller
// has already shifted with its own rounding).
constexpr q31_t sat_q63_to_q31(q63_t v) {
  if (v > INT32_MAX) return INT32_MAX;
  if (v < INT32_MIN) return INT32_MIN;
  return static_cast<q31_t>(v);
}

// Q1.31 -> Q1.15. Scaling: keeps the top 16 bits. Rounding: to nearest, ties
// up (+0.5 LSB of Q1.15). Overflow: saturates (only near +1.0).
constexpr q15_t sat_rnd_q31_to_q15(q31_t v) {
  const int64_t r = (static_cast<int64_t>(v) + (1 << 15)) >> 16;
  return static_cast<q15_t>(r > INT16_MAX ? INT16_MAX : r);
}

// Arithmetic right shift of a q63 by `shift` (1..62) bits.
// Rounding: to nearest, ties toward +inf (adds half an output LSB).
// Overflow: none for |v| < 2^62; the caller keeps inputs in that range.
constexpr q63_t rshift_q63_rnd(q63_t v, int shift) {
  return (v + (q63_t{1} << (shift - 1))) >> shift;
}

// Q1.31 + Q1.31 -> Q1.31. Overflow: saturates. Rounding: exact.
constexpr q31_t add_q31_sat(q31_t a, q31_t b) { return sat_q63_to_q31(static_cast<q63_t>(a) + b); }

// Q1.31 - Q1.31 -> Q1.31. Overflow: saturates. Rounding: exact.
constexpr q31_t sub_q31_sat(q31_t a, q31_t b) { return sat_q63_to_q31(static_cast<q63_t>(a) - b); }

// Q1.31 + Q1.31 -> Q1.31 modulo 2^32 (phase-like quantities). Overflow:
// wraps. Rounding: exact.
constexpr q31_t add_q31_wrap(q31_t a, q31_t b) {
  return static_cast<q31_t>(static_cast<uint32_t>(a) + static_cast<uint32_t>(b));
}

// Q1.31 x Q1.31 -> Q2.62, exact. Overflow: none.
constexpr q63_t mul_q31_q63(q31_t a, q31_t b) { return static_cast<q63_t>(a) * b; }

// Q1.31 x Q1.31 -> Q1.31. Rounding: to nearest, ties toward +inf.
// Overflow: saturates (only -1 x -1 overflows, giving INT32_MAX).
constexpr q31_t mul_q31_rnd(q31_t a, q31_t b) {
  return sat_q63_to_q31(rshift_q63_rnd(mul_q31_q63(a, b), 31));
}

// Signed q63 division. Rounding: to nearest, ties away from zero.
// Overflow: none for den > 0 and |num| < 2^62. den must be > 0.
constexpr q63_t div_q63_rnd(q63_t num, q63_t den) {
  return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

// double -> Q1.31. Scaling: 1.0 -> 2^31. Rounding: to nearest, ties away
// from zero. Overflow: saturates (|v| >= 1 gives the rail); NaN gives 0.
constexpr q31_t q31_from_f64_sat(double v) {
  if (!(v == v)) return 0;
  const double s = v * kQ31One;
  if (s >= 2147483647.0) return INT32_MAX;
  if (s <= -2147483648.0) return INT32_MIN;
  return static_cast<q31_t>(s >= 0.0 ? s + 0.5 : s - 0.5);
}

// Q1.31 -> double, exact.
constexpr double f64_from_q31(q31_t v) { return static_cast<double>(v) / kQ31One; }

}  // namespace hrg::dsp
