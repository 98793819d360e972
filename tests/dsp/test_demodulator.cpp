// SPDX-License-Identifier: MIT
// Demodulator: golden vectors from a double-precision direct-form reference,
// 2f image rejection, rails.
#include "dsp/demodulator.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <vector>

#include "support/cpputest.hpp"

using namespace hrg::dsp;

namespace {
constexpr double kFs = 100000.0;
constexpr uint32_t kL = 100;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Q1.31 pickoff samples of x = a cos(w t + p), y = b cos(w t + q) plus an
// optional second tone, rounded to nearest.
std::vector<q31_t> make_frames(std::size_t frames, double f_hz, double ax, double px, double ay,
                               double py) {
  std::vector<q31_t> v(2 * frames);
  for (std::size_t n = 0; n < frames; ++n) {
    const double wt = kTwoPi * f_hz * static_cast<double>(n) / kFs;
    v[2 * n] = q31_from_f64_sat(ax * std::cos(wt + px));
    v[2 * n + 1] = q31_from_f64_sat(ay * std::cos(wt + py));
  }
  return v;
}

// Direct-form reference: sinc^3 taps (3L - 2, built by convolving three
// boxcars), reference signal from `ref` (ideal or the Q1.31 table), all in
// double. Output k is at the end of block k.
template <typename RefFn>
std::vector<std::array<double, 4>> reference_demod(const std::vector<q31_t>& frames, uint32_t step,
                                                   RefFn ref) {
  std::vector<double> h(1, 1.0);
  for (int stage = 0; stage < 3; ++stage) {
    std::vector<double> g(h.size() + kL - 1, 0.0);
    for (std::size_t i = 0; i < h.size(); ++i)
      for (uint32_t j = 0; j < kL; ++j)
        g[i + j] += h[i];
    h = g;
  }
  const double norm = static_cast<double>(kL) * kL * kL;
  const std::size_t n_frames = frames.size() / 2;
  std::vector<std::array<double, 4>> u(n_frames);
  for (std::size_t n = 0; n < n_frames; ++n) {
    const uint32_t ph = static_cast<uint32_t>(step * n);
    const double c = ref(ph + (1u << 30));
    const double s = ref(ph);
    const double x = f64_from_q31(frames[2 * n]);
    const double y = f64_from_q31(frames[2 * n + 1]);
    u[n] = {x * c, x * s, y * c, y * s};
  }
  std::vector<std::array<double, 4>> out(n_frames / kL);
  for (std::size_t b = 0; b < out.size(); ++b) {
    const std::size_t end = (b + 1) * kL - 1;
    std::array<double, 4> acc{};
    for (std::size_t t = 0; t < h.size() && t <= end; ++t)
      for (int k = 0; k < 4; ++k)
        acc[k] += h[t] * u[end - t][k];
    for (int k = 0; k < 4; ++k)
      out[b][k] = 2.0 * acc[k] / norm;
  }
  return out;
}

template <typename T>
std::vector<std::array<double, 4>> run_demod(const std::vector<q31_t>& frames, uint32_t step) {
  Demodulator<T> d(kL);
  uint32_t phase = 0;
  std::vector<std::array<double, 4>> out;
  for (std::size_t b = 0; b < frames.size() / (2 * kL); ++b) {
    QuadSample<T> q;
    CHECK(d.process_block(std::span<const q31_t>(frames.data() + 2 * kL * b, 2 * kL), phase, step,
                          q));
    out.push_back({SampleOps<T>::to_f64(q.cx), SampleOps<T>::to_f64(q.sx),
                   SampleOps<T>::to_f64(q.cy), SampleOps<T>::to_f64(q.sy)});
  }
  return out;
}
}  // namespace

TEST_GROUP(Demodulator){};

TEST(Demodulator, FixedMatchesTheDoubleReferenceWithinTwoLsb) {
  // GIVEN a 5001.3 Hz tone pair (not on the periodicity rule) at 0.6 / 0.3 FS
  const uint32_t step = phase_step_of_hz(5001.3, kFs);
  const auto frames = make_frames(20 * kL, 5001.3, 0.6, 0.4, 0.3, -1.1);
  // WHEN the fixed-point chain and the direct-form double reference (same
  // Q1.31 reference signal) process it
  const auto got = run_demod<q31_t>(frames, step);
  const auto ref =
      reference_demod(frames, step, [](uint32_t ph) { return f64_from_q31(sin_turns<q31_t>(ph)); });
  // THEN every output is within 2 LSB of the reference
  double worst_lsb = 0.0;
  for (std::size_t b = 0; b < got.size(); ++b)
    for (int k = 0; k < 4; ++k)
      worst_lsb = std::fmax(worst_lsb, std::fabs(got[b][k] - ref[b][k]) * kQ31One);
  CHECK(worst_lsb <= 2.0);
}

TEST(Demodulator, AllTypesMatchTheIdealReferenceWithinTheSineBound) {
  // Reference with exact sin/cos: differences come only from the table
  // (4.8e-6 of full scale, dsp/nco.hpp) and the sample type's rounding.
  const uint32_t step = phase_step_of_hz(4998.7, kFs);
  const auto frames = make_frames(20 * kL, 4998.7, 0.5, 2.0, 0.45, 0.3);
  const auto ref = reference_demod(
      frames, step, [](uint32_t ph) { return std::sin(kTwoPi * ph / 4294967296.0); });
  const auto q = run_demod<q31_t>(frames, step);
  const auto f = run_demod<float>(frames, step);
  const auto d = run_demod<double>(frames, step);
  for (std::size_t b = 3; b < ref.size(); ++b) {
    for (int k = 0; k < 4; ++k) {
      DOUBLES_EQUAL(ref[b][k], q[b][k], 4.8e-6 * 0.5);
      DOUBLES_EQUAL(ref[b][k], d[b][k], 4.8e-6 * 0.5);
      DOUBLES_EQUAL(ref[b][k], f[b][k], 4.8e-6 * 0.5 + 2e-7);
      // fixed vs double chain: the same algorithm, only roundings differ
      DOUBLES_EQUAL(d[b][k], q[b][k], 3.0 / kQ31One);
    }
  }
}

TEST(Demodulator, RejectsTheTwoFImageByAtLeast100Db) {
  // GIVEN tones exactly at the NCO frequency with the resonance on and off
  // the periodicity rule: the true quadratures are constant, so any ripple
  // of the output is the 2f image leaking through.
  double worst_db = -400.0, worst_f = 0.0, worst_formula_db = 0.0;
  for (double f : {5000.0, 5000.4, 4998.0, 5002.0, 5010.0, 4950.0, 5100.0}) {
    const double a = 0.5, p = 0.7;
    const uint32_t step = phase_step_of_hz(f, kFs);
    const double f_nco = hz_of_phase_step(step, kFs);
    const auto frames = make_frames(12 * kL, f_nco, a, p, a, p + 1.0);
    const auto d = run_demod<double>(frames, step);
    // The table's gain error (~3e-6, common to all outputs) is a constant
    // offset; the image is what varies from block to block.
    double worst = 0.0;
    for (int k = 0; k < 2; ++k) {
      double mean = 0.0;
      for (std::size_t b = 3; b < d.size(); ++b)
        mean += d[b][k] / static_cast<double>(d.size() - 3);
      for (std::size_t b = 3; b < d.size(); ++b)
        worst = std::fmax(worst, std::fabs(d[b][k] - mean));
      const double truth = k == 0 ? a * std::cos(p) : -a * std::sin(p);
      DOUBLES_EQUAL(truth, mean, 5e-6 * a);
    }
    // THEN the leak is >= 100 dB below the amplitude, as the formula predicts
    const double measured_db = 20.0 * std::log10(worst / a);
    CHECK(image_rejection_db(2 * f_nco, kFs, kL) <= -100.0);
    CHECK(measured_db <= -100.0);
    if (measured_db > worst_db) {
      worst_db = measured_db;
      worst_f = f;
      worst_formula_db = image_rejection_db(2 * f_nco, kFs, kL);
    }
  }
  std::printf("\n  2f image: worst %.1f dB at f = %.1f Hz (formula %.1f dB)\n", worst_db, worst_f,
              worst_formula_db);
  // and the formula says where the guarantee ends: 2f 231 Hz off the rule
  CHECK(image_rejection_db(2 * 5115.0, kFs, kL) < -100.0);
  CHECK(image_rejection_db(2 * 5250.0, kFs, kL) > -100.0);
}

TEST(Demodulator, SaturatesAtTheRailsForAFullScaleSquareWave) {
  // GIVEN x = y = a full-scale square wave in phase with cos: |2 <x cos>| = 4/pi > 1
  std::vector<q31_t> frames(2 * 10 * kL);
  const uint32_t step = phase_step_of_hz(5000.0, kFs);
  for (std::size_t n = 0; n < frames.size() / 2; ++n) {
    const bool hi = cos_turns<double>(static_cast<uint32_t>(step * n)) >= 0.0;
    frames[2 * n] = hi ? INT32_MAX : INT32_MIN;
    frames[2 * n + 1] = hi ? INT32_MIN : INT32_MAX;
  }
  const auto q = run_demod<q31_t>(frames, step);
  // THEN cx sits on the positive rail and cy on the negative one (no wrap)
  CHECK_EQUAL(static_cast<double>(INT32_MAX) / kQ31One, q.back()[0]);
  CHECK_EQUAL(-1.0, q.back()[2]);
  // and the float chain reports the true value, 2/20 sum |cos(18 deg k)| (the
  // sampled version of 4/pi) instead
  double expected = 0.0;
  for (int k = 0; k < 20; ++k)
    expected += 0.1 * std::fabs(std::cos(kTwoPi * k / 20.0));
  CHECK(expected > 1.2);
  const auto f = run_demod<double>(frames, step);
  DOUBLES_EQUAL(expected, f.back()[0], 1e-5);
}

TEST(Demodulator, RefusesABlockOfTheWrongSize) {
  Demodulator<q31_t> d(kL);
  std::vector<q31_t> frames(2 * kL - 2, 0);
  uint32_t phase = 123;
  QuadSample<q31_t> q;
  CHECK_FALSE(d.process_block(frames, phase, 1000, q));
  CHECK_EQUAL(123u, phase);
}
