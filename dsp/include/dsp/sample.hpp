// SPDX-License-Identifier: MIT
#pragma once

// Arithmetic of one sample type, so each kernel is written once for float,
// double and Q1.31. The fast path takes Q1.31 converter words in all three
// variants and works in `SampleOps<T>::value_t`.

#include <cstdint>
#include <type_traits>

#include "dsp/fixed.hpp"

// Per-sample helpers are forced inline: at -Os (the bare-metal build) the
// compiler would otherwise call them once per sample.
#if defined(__GNUC__)
#define HRG_DSP_INLINE [[gnu::always_inline]] inline
#else
#define HRG_DSP_INLINE inline
#endif

namespace hrg::dsp {

template <typename T>
struct SampleOps;

// Floating point: 1.0 is the converter's full scale.
template <typename F>
struct FloatSampleOps {
  using value_t = F;
  using acc_t = F;  // sums of mixing products over a block
  static constexpr bool kFixed = false;

  HRG_DSP_INLINE static value_t from_q31(q31_t v) { return static_cast<F>(v) * F(1.0 / kQ31One); }
  // Rounding: to nearest, ties away from zero. Overflow: saturates.
  static q31_t to_q31(value_t v) { return q31_from_f64_sat(static_cast<double>(v)); }
  static double to_f64(value_t v) { return static_cast<double>(v); }
  static double acc_to_f64(acc_t v) { return static_cast<double>(v); }
  // Mixing product x * ref. Exact up to the float rounding of the product.
  HRG_DSP_INLINE static acc_t mix(value_t x, value_t ref) { return x * ref; }
  // a * b in the value scale.
  static value_t mul(value_t a, value_t b) { return a * b; }
  static value_t add(value_t a, value_t b) { return a + b; }
  // a c + b s -> Q1.31 converter word, rounding to nearest, saturating.
  HRG_DSP_INLINE static q31_t mac2_to_q31(value_t a, value_t c, value_t b, value_t s) {
    return to_q31(a * c + b * s);
  }
};

template <>
struct SampleOps<float> : FloatSampleOps<float> {};
template <>
struct SampleOps<double> : FloatSampleOps<double> {};

// Q1.31: 2^31 is the converter's full scale; sums of mixing products are q63
// in Q1.31 units (a sum of L products needs 31 + log2(L) bits).
template <>
struct SampleOps<q31_t> {
  using value_t = q31_t;
  using acc_t = q63_t;
  static constexpr bool kFixed = true;

  HRG_DSP_INLINE static value_t from_q31(q31_t v) { return v; }
  static q31_t to_q31(value_t v) { return v; }
  static double to_f64(value_t v) { return f64_from_q31(v); }
  static double acc_to_f64(acc_t v) { return static_cast<double>(v) / kQ31One; }
  // Mixing product: Q1.31 x Q1.31 -> Q2.62 -> Q1.31 units held in a q63, so
  // -1 x -1 = +1 does not overflow. Rounding: to nearest, ties toward +inf.
  HRG_DSP_INLINE static acc_t mix(value_t x, value_t ref) {
    return rshift_q63_rnd(mul_q31_q63(x, ref), 31);
  }
  // Q1.31 x Q1.31 -> Q1.31, rounding to nearest, saturating.
  static value_t mul(value_t a, value_t b) { return mul_q31_rnd(a, b); }
  // Saturating add.
  static value_t add(value_t a, value_t b) { return add_q31_sat(a, b); }
  // a c + b s -> Q1.31 (drive synthesis: coefficients a, b, table values c, s).
  // Input scaling: Q1.31; |c|, |s| <= 1 - 2^-31 (sin_turns never returns -1).
  // Overflow: the Q2.62 sum stays below 2^63 for any a, b; the result
  // saturates to Q1.31. Rounding: once, to nearest, ties toward +inf.
  HRG_DSP_INLINE static q31_t mac2_to_q31(value_t a, value_t c, value_t b, value_t s) {
    return sat_q63_to_q31(rshift_q63_rnd(mul_q31_q63(a, c) + mul_q31_q63(b, s), 31));
  }
};

}  // namespace hrg::dsp
