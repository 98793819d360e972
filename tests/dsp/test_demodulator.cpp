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
#include "support/decimator_taps.hpp"

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

// Direct-form reference: sinc^N taps (N (L - 1) + 1, built by convolving N
// boxcars), reference signal from `ref` (ideal or the Q1.31 table), all in
// double. Output k is at the end of block k.
template <typename RefFn>
std::vector<std::array<double, 4>> reference_demod(const std::vector<q31_t>& frames, uint32_t step,
                                                   RefFn ref) {
  std::vector<double> h(1, 1.0);
  for (uint32_t stage = 0; stage < kDecimatorOrder; ++stage) {
    std::vector<double> g(h.size() + kL - 1, 0.0);
    for (std::size_t i = 0; i < h.size(); ++i)
      for (uint32_t j = 0; j < kL; ++j)
        g[i + j] += h[i];
    h = g;
  }
  const double norm = std::pow(static_cast<double>(kL), kDecimatorOrder);
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

TEST(Demodulator, FixedMatchesTheDoubleReferenceWithinItsRoundingBound) {
  // GIVEN a 5001.3 Hz tone pair (not on the periodicity rule) at 0.6 / 0.3 FS
  const uint32_t step = phase_step_of_hz(5001.3, kFs);
  const auto frames = make_frames(20 * kL, 5001.3, 0.6, 0.4, 0.3, -1.1);
  // WHEN the fixed-point chain and the direct-form double reference (same
  // Q1.31 reference signal) process it
  const auto got = run_demod<q31_t>(frames, step);
  const auto ref =
      reference_demod(frames, step, [](uint32_t ph) { return f64_from_q31(sin_turns<q31_t>(ph)); });
  // THEN every output is within the contract's 2^h + 1/2 LSB (products
  // rounded at 2^-(31-h), h = 3 for L = 100) of the reference
  const int h = Demodulator<q31_t>::headroom_bits(kL);
  CHECK_EQUAL(3, h);
  double worst_lsb = 0.0;
  for (std::size_t b = 0; b < got.size(); ++b)
    for (int k = 0; k < 4; ++k)
      worst_lsb = std::fmax(worst_lsb, std::fabs(got[b][k] - ref[b][k]) * kQ31One);
  std::printf("\n  fixed vs double reference: worst %.2f LSB (bound %.1f)\n", worst_lsb,
              std::ldexp(1.0, h) + 0.5);
  CHECK(worst_lsb <= std::ldexp(1.0, h) + 0.5);
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
  for (std::size_t b = kDecimatorOrder; b < ref.size(); ++b) {
    for (int k = 0; k < 4; ++k) {
      DOUBLES_EQUAL(ref[b][k], q[b][k], 4.8e-6 * 0.5);
      DOUBLES_EQUAL(ref[b][k], d[b][k], 4.8e-6 * 0.5);
      DOUBLES_EQUAL(ref[b][k], f[b][k], 4.8e-6 * 0.5 + 2e-7);
      // fixed vs double chain: the same algorithm, only roundings differ
      DOUBLES_EQUAL(d[b][k], q[b][k], 9.0 / kQ31One);
    }
  }
}

namespace {
// Measured 2f image, relative to the amplitude, for a resonance at f_hz: two
// runs with the tone coherent with the NCO, the second a quarter turn later.
// Everything that does not depend on the phase (the wanted DC, the table's
// gain error and its spurs, which repeat every quarter turn) cancels in the
// difference; the 2f image (e^(2i phase)) changes sign. Half the difference
// is the image; the worst over the settled outputs is returned.
template <typename T>
double measured_image(double f_hz, uint32_t blocks) {
  const uint32_t step = phase_step_of_hz(f_hz, kFs);
  const double a = 0.5;
  std::vector<std::array<double, 4>> out[2];
  for (int run = 0; run < 2; ++run) {
    const uint32_t start = 0x12345678u + (run == 0 ? 0u : (1u << 30));
    std::vector<q31_t> frames(2 * blocks * kL);
    for (std::size_t n = 0; n < blocks * kL; ++n) {
      const double th = kTwoPi * static_cast<uint32_t>(start + step * n) / 4294967296.0;
      frames[2 * n] = q31_from_f64_sat(a * std::cos(th));
      frames[2 * n + 1] = q31_from_f64_sat(a * std::cos(th + 1.0));
    }
    Demodulator<T> d(kL);
    uint32_t phase = start;
    for (uint32_t b = 0; b < blocks; ++b) {
      QuadSample<T> q;
      d.process_block(std::span<const q31_t>(frames.data() + 2 * kL * b, 2 * kL), phase, step, q);
      out[run].push_back({SampleOps<T>::to_f64(q.cx), SampleOps<T>::to_f64(q.sx),
                          SampleOps<T>::to_f64(q.cy), SampleOps<T>::to_f64(q.sy)});
    }
  }
  double worst = 0.0;
  for (uint32_t b = kDecimatorOrder; b < blocks; ++b)
    for (int ch = 0; ch < 2; ++ch) {
      const double dc = (out[0][b][2 * ch] - out[1][b][2 * ch]) / 2.0;
      const double ds = (out[0][b][2 * ch + 1] - out[1][b][2 * ch + 1]) / 2.0;
      worst = std::fmax(worst, std::hypot(dc, ds) / a);
    }
  return worst;
}
}  // namespace

TEST(Demodulator, RejectsTheTwoFImageByAtLeast100DbForAnyResonanceFrom2To12Khz) {
  // GIVEN resonances every 7 Hz from 2 to 12 kHz (on and off any multiple of
  // the output rate), fixed and float, 6 settled outputs each
  for (int type = 0; type < 2; ++type) {
    double worst_db = -400.0, worst_f = 0.0, worst_formula_db = -400.0;
    for (double f = 2000.0; f <= 12000.0; f += 7.0) {
      const double rel = type == 0 ? measured_image<q31_t>(f, kDecimatorOrder + 6)
                                   : measured_image<float>(f, kDecimatorOrder + 6);
      const double db = 20.0 * std::log10(std::fmax(rel, 1e-20));
      const double formula_db = image_rejection_db(2.0 * f, kFs, kL);
      worst_formula_db = std::fmax(worst_formula_db, formula_db);
      if (db > worst_db) {
        worst_db = db;
        worst_f = f;
      }
      // THEN the image is >= 100 dB down everywhere
      CHECK(db <= -100.0);
      CHECK(formula_db <= -100.0);
    }
    std::printf(
        "\n  2f image, %s, 2..12 kHz every 7 Hz: worst measured %.1f dB at %.0f Hz "
        "(formula worst %.1f dB)\n",
        type == 0 ? "Q1.31" : "float", worst_db, worst_f, worst_formula_db);
  }
  // AND the band the decimator serves is derived from the envelope bound
  const DecimatorBand band = decimator_band(kFs, kL);
  DOUBLES_EQUAL(1594.2, band.lo_hz, 0.1);
  DOUBLES_EQUAL(kFs / 2.0 - 1594.2, band.hi_hz, 0.1);
  CHECK(image_rejection_db(2.0 * band.lo_hz, kFs, kL) <= -100.0);
  // and a resonance below it is not served: the image there can be < 100 dB down
  CHECK(image_rejection_db(2.0 * 1250.0, kFs, kL) > -100.0);
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

TEST(Demodulator, TheRowsNoiseCorrelationIsThatOfItsOwnFilter) {
  // GIVEN the decimator's taps (boxcar_L^N) for L = 1, 4, 100
  for (uint32_t l : {1u, 4u, 100u}) {
    const std::vector<double> h = hrg::test::decimator_taps(l);
    // WHEN the correlation of outputs m blocks apart, R(mL) / R(0), is
    // summed over every lag
    double r0 = 0.0;
    for (double v : h)
      r0 += v * v;
    double sum_rho = 0.0;
    const auto n_taps = static_cast<long>(h.size());
    for (long m = -n_taps; m <= n_taps; ++m) {
      double r = 0.0;
      for (long i = 0; i < n_taps; ++i) {
        const long j = i + m * static_cast<long>(l);
        if (j >= 0 && j < n_taps) r += h[i] * h[j];
      }
      sum_rho += r / r0;
    }
    // THEN it is the closed form (1 for L = 1: no overlap)
    DOUBLES_EQUAL(sum_rho, decimator_row_noise_correlation(l), 1e-9 * sum_rho);
  }
  // AND at L = 100 it is near its large-L limit 1 / B_10(0) = 362880 / 156190
  DOUBLES_EQUAL(1.0, decimator_row_noise_correlation(1), 1e-12);
  DOUBLES_EQUAL(362880.0 / 156190.0, decimator_row_noise_correlation(100), 1e-3);
}
