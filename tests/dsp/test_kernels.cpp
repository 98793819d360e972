// SPDX-License-Identifier: MIT
// Fixed-point helpers, NCO and sine/cosine: contracts held at the rails.
#include "dsp/fixed.hpp"
#include "dsp/nco.hpp"
#include "dsp/sample.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>

#include "support/cpputest.hpp"

using namespace hrg::dsp;

TEST_GROUP(FixedHelpers){};

TEST(FixedHelpers, SaturateAtBothRailsInsteadOfWrapping) {
  CHECK_EQUAL(INT32_MAX, add_q31_sat(INT32_MAX, 1));
  CHECK_EQUAL(INT32_MIN, add_q31_sat(INT32_MIN, -1));
  CHECK_EQUAL(INT32_MIN, sub_q31_sat(INT32_MIN, 1));
  CHECK_EQUAL(INT32_MAX, sub_q31_sat(INT32_MAX, -1));
  CHECK_EQUAL(INT32_MAX, sat_q63_to_q31(INT64_MAX));
  CHECK_EQUAL(INT32_MIN, sat_q63_to_q31(INT64_MIN));
  CHECK_EQUAL(INT16_MAX, sat_rnd_q31_to_q15(INT32_MAX));
  CHECK_EQUAL(INT16_MIN, sat_rnd_q31_to_q15(INT32_MIN));
}

TEST(FixedHelpers, WrapAddIsModuloTwoToThe32) {
  CHECK_EQUAL(INT32_MIN, add_q31_wrap(INT32_MAX, 1));
  CHECK_EQUAL(INT32_MAX, add_q31_wrap(INT32_MIN, -1));
}

TEST(FixedHelpers, MultiplyRoundsToNearestAndSaturatesMinusOneSquared) {
  CHECK_EQUAL(INT32_MAX, mul_q31_rnd(INT32_MIN, INT32_MIN));   // -1 * -1 = +1 -> rail
  CHECK_EQUAL(-INT32_MAX, mul_q31_rnd(INT32_MIN, INT32_MAX));  // -1 * (1 - 2^-31)
  // 0.5 LSB ties go up, 0.25 LSB goes down: 3 * 2^30 / 2^31 = 1.5 -> 2; 1 * 2^30 -> 0.5 -> 1
  CHECK_EQUAL(2, mul_q31_rnd(3, 1 << 30));
  CHECK_EQUAL(1, mul_q31_rnd(1, 1 << 30));
  CHECK_EQUAL(0, mul_q31_rnd(-1, 1 << 30));   // -0.5 LSB ties toward +inf
  CHECK_EQUAL(-1, mul_q31_rnd(-3, 1 << 29));  // -0.75 -> -1
}

TEST(FixedHelpers, SynthesisMacSaturatesAtTheRailsWithoutOverflowingTheSum) {
  using Ops = SampleOps<q31_t>;
  CHECK_EQUAL(INT32_MAX, Ops::mac2_to_q31(INT32_MAX, INT32_MAX, INT32_MAX, INT32_MAX));
  CHECK_EQUAL(INT32_MIN, Ops::mac2_to_q31(INT32_MIN, INT32_MAX, INT32_MIN, INT32_MAX));
  CHECK_EQUAL(INT32_MAX, Ops::mac2_to_q31(INT32_MIN, -INT32_MAX, INT32_MIN, -INT32_MAX));
  // 0.5 * 0.5 + 0.25 * 0.5 = 0.375, exact; ties of the single rounding go up
  CHECK_EQUAL(3 << 28, Ops::mac2_to_q31(1 << 30, 1 << 30, 1 << 29, 1 << 30));
  CHECK_EQUAL(1, Ops::mac2_to_q31(1, 1 << 30, 0, 0));
  CHECK_EQUAL(0, Ops::mac2_to_q31(-1, 1 << 30, 0, 0));
  // float twin: same arithmetic, saturating conversion
  CHECK_EQUAL(INT32_MAX, SampleOps<float>::mac2_to_q31(1.0f, 1.0f, 1.0f, 1.0f));
  CHECK_EQUAL(INT32_MIN, SampleOps<double>::mac2_to_q31(-1.0, 1.0, -1.0, 1.0));
}

TEST(FixedHelpers, ConversionFromDoubleRoundsAndSaturates) {
  CHECK_EQUAL(INT32_MAX, q31_from_f64_sat(1.0));
  CHECK_EQUAL(INT32_MAX, q31_from_f64_sat(1e300));
  CHECK_EQUAL(INT32_MIN, q31_from_f64_sat(-1.0));
  CHECK_EQUAL(INT32_MIN, q31_from_f64_sat(-7.0));
  CHECK_EQUAL(0, q31_from_f64_sat(std::nan("")));
  CHECK_EQUAL(1, q31_from_f64_sat(0.5 / kQ31One));    // tie away from zero
  CHECK_EQUAL(-1, q31_from_f64_sat(-0.5 / kQ31One));  // tie away from zero
  CHECK_EQUAL(0, q31_from_f64_sat(0.49 / kQ31One));
  DOUBLES_EQUAL(-1.0, f64_from_q31(INT32_MIN), 0.0);
}

TEST(FixedHelpers, DivisionRoundsToNearestTiesAwayFromZero) {
  CHECK_EQUAL(2, div_q63_rnd(3, 2));
  CHECK_EQUAL(-2, div_q63_rnd(-3, 2));
  CHECK_EQUAL(1, div_q63_rnd(4, 3));
  CHECK_EQUAL(-1, div_q63_rnd(-4, 3));
  CHECK_EQUAL(INT64_C(1) << 61, div_q63_rnd((INT64_C(1) << 62) - 1, 2));
}

TEST_GROUP(SineCosine){};

template <typename T>
static double max_sine_error(bool cosine) {
  double worst = 0.0;
  for (uint64_t k = 0; k < (uint64_t{1} << 20); ++k) {
    // Scatter the phases over all 32 bits (odd multiplier: a permutation).
    const uint32_t ph = static_cast<uint32_t>(k * 2654435761u);
    const double ideal = cosine ? std::cos(2.0 * std::numbers::pi * ph / 4294967296.0)
                                : std::sin(2.0 * std::numbers::pi * ph / 4294967296.0);
    const T v = cosine ? cos_turns<T>(ph) : sin_turns<T>(ph);
    const double got = SampleOps<T>::to_f64(v);
    worst = std::fmax(worst, std::fabs(got - ideal));
  }
  return worst;
}

TEST(SineCosine, StayWithinTheStatedBoundForEveryType) {
  // Bound: (2 pi / 1024)^2 / 8 = 4.706e-6 plus rounding (see nco.hpp).
  const double bound = 4.8e-6;
  for (bool c : {false, true}) {
    const double eq = max_sine_error<q31_t>(c);
    const double ef = max_sine_error<float>(c);
    const double ed = max_sine_error<double>(c);
    CHECK(eq < bound);
    CHECK(ef < bound);
    CHECK(ed < bound);
    // The bound is tight: interpolation error really is ~4.7e-6.
    CHECK(ed > 4.6e-6);
  }
}

TEST(SineCosine, FixedNeverReachesMinusOneAndHitsTheRailsExactly) {
  CHECK_EQUAL(INT32_MAX, sin_turns<q31_t>(1u << 30));  // sin 90 deg
  CHECK_EQUAL(-INT32_MAX, sin_turns<q31_t>(3u << 30));
  CHECK_EQUAL(0, sin_turns<q31_t>(0));
  CHECK_EQUAL(0, sin_turns<q31_t>(1u << 31));
  CHECK_EQUAL(INT32_MAX, cos_turns<q31_t>(0));
  CHECK_EQUAL(-INT32_MAX, cos_turns<q31_t>(1u << 31));
  for (uint32_t ph = 0xFFF00000u; ph != 0x00100000u; ph += 0x1000u) {
    CHECK(sin_turns<q31_t>(ph) > INT32_MIN);
    CHECK(cos_turns<q31_t>(ph) > INT32_MIN);
  }
  // Last segment interpolates toward the guard entry, not past the table end.
  CHECK(std::fabs(f64_from_q31(sin_turns<q31_t>(0xFFFFFFFFu))) < 1e-8);
}

TEST_GROUP(Nco){};

TEST(Nco, PhaseWrapsModuloOneTurnWithoutDrift) {
  Nco nco;
  const uint32_t step = phase_step_of_hz(5000.0, 100000.0);
  CHECK_EQUAL(214748365u, step);  // 2^32 / 20, rounded
  nco.set_step(step);
  // 20 steps = one turn minus the rounding (20 * step - 2^32 = 4 LSB)
  for (int k = 0; k < 20; ++k)
    nco.advance(1);
  CHECK_EQUAL(4u, nco.phase());
  // 10^6 blocks of 100 samples later the phase is exactly step * n mod 2^32
  for (int k = 0; k < 1000000; ++k)
    nco.advance(100);
  CHECK_EQUAL(static_cast<uint32_t>(4u + step * 100000000ull), nco.phase());
}

TEST(Nco, StepConversionRoundsAndWrapsNegativeFrequencies) {
  DOUBLES_EQUAL(5001.25, hz_of_phase_step(phase_step_of_hz(5001.25, 1e5), 1e5), 1e5 / 4.3e9);
  CHECK_EQUAL(phase_step_of_hz(99000.0, 1e5), phase_step_of_hz(-1000.0, 1e5));
  CHECK_EQUAL(1u << 29, phase_of_rad(std::numbers::pi / 4));
  CHECK_EQUAL(3u << 30, phase_of_rad(-std::numbers::pi / 2));
}
