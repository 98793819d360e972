// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

namespace hrg::dsp {

// CMSIS-style fixed-point vocabulary. Qm.n: m integer bits (sign included), n fraction bits.
using q15_t = int16_t;  // Q1.15
using q31_t = int32_t;  // Q1.31
using q63_t = int64_t;  // Q1.63, or Q2.62 for a product of two Q1.31 values

// Q2.62 (or any q63 accumulator scaled like Q1.63 >> 32) -> Q1.31.
// Overflow: saturates to [INT32_MIN, INT32_MAX]. Rounding: none (the caller
// has already shifted with its own rounding).
constexpr q31_t sat_q63_to_q31(q63_t v) {
  if (v > INT32_MAX) return INT32_MAX;
  if (v < INT32_MIN) return INT32_MIN;
  return static_cast<q31_t>(v);
}

}  // namespace hrg::dsp
