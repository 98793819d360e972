// SPDX-License-Identifier: MIT
// Fixed-point suite that runs unchanged on the host and on the Cortex-M7
// (QEMU mps2-an500): the Q1.31 helpers at their rails, sine/cosine against
// their bound, the NCO, the demodulator against a direct-form double
// reference, and the Q1.31 chain on synthetic blocks. Inputs are generated
// with integer arithmetic only, so both platforms see the same bits; every
// Q1.31 output goes into the digest, which must equal the committed one
// (tests/m7/fixed_suite.digest) on both.

#include <array>
#include <cmath>
#include <cstdint>
#include <span>

#include "dsp/chain.hpp"
#include "dsp/demodulator.hpp"
#include "dsp/fixed.hpp"
#include "dsp/nco.hpp"
#include "dsp/pickoff_correction.hpp"
#include "report.hpp"

namespace hrg::m7 {

using namespace hrg::dsp;

namespace {

constexpr uint32_t kL = 100;
constexpr double kFs = 100000.0;

// Deterministic pseudo-noise (LCG), integer only.
struct Lcg {
  uint32_t s = 12345u;
  int32_t next(int32_t amplitude_lsb) {
    s = s * 1664525u + 1013904223u;
    return static_cast<int32_t>((s >> 8) % (2u * static_cast<uint32_t>(amplitude_lsb) + 1u)) -
           amplitude_lsb;
  }
};

// Interleaved x, y frames: amplitude * sin(phase + offsets) + noise, from the
// project's own Q1.31 NCO.
void make_block(std::span<q31_t> frames, uint32_t& phase, uint32_t step, q31_t ax, q31_t ay,
                uint32_t px, uint32_t py, Lcg& noise) {
  for (std::size_t n = 0; n < frames.size() / 2; ++n) {
    frames[2 * n] = add_q31_sat(mul_q31_rnd(ax, sin_turns<q31_t>(phase + px)), noise.next(4096));
    frames[2 * n + 1] =
        add_q31_sat(mul_q31_rnd(ay, sin_turns<q31_t>(phase + py)), noise.next(4096));
    phase += step;
  }
}

void helpers_at_the_rails(Report& r) {
  r.check(add_q31_sat(kQ31Max, 1) == kQ31Max, "add_q31_sat saturates up");
  r.check(add_q31_sat(kQ31Min, -1) == kQ31Min, "add_q31_sat saturates down");
  r.check(sub_q31_sat(kQ31Min, 1) == kQ31Min, "sub_q31_sat saturates");
  r.check(add_q31_wrap(kQ31Max, 1) == kQ31Min, "add_q31_wrap wraps");
  r.check(mul_q31_rnd(kQ31Min, kQ31Min) == kQ31Max, "mul_q31_rnd -1*-1 saturates");
  r.check(mul_q31_rnd(3, 1 << 30) == 2, "mul_q31_rnd ties up");
  r.check(mul_q31_rnd(-1, 1 << 30) == 0, "mul_q31_rnd ties toward +inf");
  r.check(div_q63_rnd(-3, 2) == -2, "div_q63_rnd ties away from zero");
  r.check(q31_from_f64_sat(2.0) == kQ31Max && q31_from_f64_sat(-2.0) == kQ31Min,
          "q31_from_f64_sat saturates");
  r.check(sat_rnd_q31_to_q15(kQ31Max) == INT16_MAX, "sat_rnd_q31_to_q15 saturates");
  using Ops = SampleOps<q31_t>;
  r.check(Ops::mac2_to_q31(kQ31Max, kQ31Max, kQ31Max, kQ31Max) == kQ31Max, "mac2 saturates up");
  r.check(Ops::mac2_to_q31(kQ31Min, kQ31Max, kQ31Min, kQ31Max) == kQ31Min, "mac2 saturates down");
  r.check(Ops::mac2_to_q31(-1, 1 << 30, 0, 0) == 0, "mac2 ties toward +inf");
  for (q31_t v : std::array<q31_t, 4>{kQ31Max, kQ31Min, 0x12345678, -0x0FEDCBA9}) {
    r.digest_word(mul_q31_rnd(v, 0x5A5A5A5A));
    r.digest_word(add_q31_sat(v, v));
  }
}

void sine_within_its_bound(Report& r) {
  double worst = 0.0;
  for (uint32_t k = 0; k < 65536u; ++k) {
    const uint32_t ph = k * 2654435761u;
    const q31_t s = sin_turns<q31_t>(ph);
    const q31_t c = cos_turns<q31_t>(ph);
    const double a = 6.283185307179586 * static_cast<double>(ph) / 4294967296.0;
    worst = std::fmax(worst, std::fabs(f64_from_q31(s) - std::sin(a)));
    worst = std::fmax(worst, std::fabs(f64_from_q31(c) - std::cos(a)));
    r.check(s != kQ31Min && c != kQ31Min, "sine never reaches -1.0");
    if ((k & 15u) == 0u) {
      r.digest_word(s);
      r.digest_word(c);
    }
  }
  r.figure("sine max error (1e-9 FS)", static_cast<int64_t>(worst * 1e9));
  r.check(worst < 4.8e-6, "sine error bound 4.8e-6");
}

void nco_wraps(Report& r) {
  Nco nco;
  const uint32_t step = phase_step_of_hz(5000.0, kFs);
  r.check(step == 214748365u, "NCO step of 5 kHz at 100 kHz");
  nco.set_step(step);
  for (int k = 0; k < 100000; ++k)
    nco.advance(kL);
  r.check(nco.phase() == static_cast<uint32_t>(step * 10000000ull), "NCO phase wraps exactly");
  r.digest_word(static_cast<int32_t>(nco.phase()));
}

// Direct-form sinc^5 reference for the last output of a run, in double.
void demodulator_matches_reference(Report& r) {
  static std::array<q31_t, 2 * kL * 8> frames;
  double worst_lsb = 0.0;
  for (double f : {5000.0, 5001.3, 4998.2}) {
    const uint32_t step = phase_step_of_hz(f, kFs);
    uint32_t gen_phase = 0x1234567u;
    Lcg noise;
    make_block(frames, gen_phase, step, 0x4CCCCCCC, 0x26666666, 0u, 0x3000000u, noise);
    Demodulator<q31_t> d(kL);
    uint32_t phase = 0;
    QuadSample<q31_t> q;
    for (uint32_t b = 0; b < 8; ++b) {
      d.process_block(std::span<const q31_t>(frames.data() + 2 * kL * b, 2 * kL), phase, step, q);
      r.digest_word(q.cx);
      r.digest_word(q.sx);
      r.digest_word(q.cy);
      r.digest_word(q.sy);
    }
    // Reference: output at the end of block 7 = taps h[t] over the last
    // N (L - 1) + 1 frames, h the discrete B-spline (ways to write t as a sum
    // of N integers in [0, L)).
    double acc[4] = {0, 0, 0, 0};
    const uint32_t end = 8 * kL - 1;
    for (uint32_t t = 0; t < kDecimatorOrder * (kL - 1) + 1; ++t) {
      const double h = static_cast<double>(DecimatorWeights::bspline(t, kL));
      const uint32_t n = end - t;
      const uint32_t ph = step * n;
      const double c = f64_from_q31(cos_turns<q31_t>(ph));
      const double s = f64_from_q31(sin_turns<q31_t>(ph));
      const double x = f64_from_q31(frames[2 * n]);
      const double y = f64_from_q31(frames[2 * n + 1]);
      acc[0] += h * x * c;
      acc[1] += h * x * s;
      acc[2] += h * y * c;
      acc[3] += h * y * s;
    }
    const q31_t got[4] = {q.cx, q.sx, q.cy, q.sy};
    for (int k = 0; k < 4; ++k) {
      const double ref = 2.0 * acc[k] / 1e10;
      worst_lsb = std::fmax(worst_lsb, std::fabs(f64_from_q31(got[k]) - ref) * kQ31One);
    }
  }
  r.figure("demodulator vs double reference (1e-3 LSB)", static_cast<int64_t>(worst_lsb * 1e3));
  r.check(worst_lsb <= 8.5, "demodulator within 2^h + 1/2 LSB (h = 3) of the reference");
}

// The decimator at the rails: a full-scale square wave in phase with cos on
// x (and inverted on y) for every block length, down to the longest (h = 24):
// 2 <x cos> = 4/pi saturates to the rails, never wraps.
void demodulator_at_the_rails(Report& r) {
  static std::array<q31_t, 2 * 2000> frames;
  for (uint32_t l : {4u, 100u, 2000u}) {
    const uint32_t step = phase_step_of_hz(l == 4 ? 12500.0 : 5000.0, kFs);
    Demodulator<q31_t> d(l);
    uint32_t phase = 0;
    QuadSample<q31_t> q;
    for (uint32_t b = 0; b < 7; ++b) {
      uint32_t ph = phase;
      for (uint32_t n = 0; n < l; ++n, ph += step) {
        const bool hi = cos_turns<q31_t>(ph) >= 0;
        frames[2 * n] = hi ? INT32_MAX : INT32_MIN;
        frames[2 * n + 1] = hi ? INT32_MIN : INT32_MAX;
      }
      d.process_block(std::span<const q31_t>(frames.data(), 2 * l), phase, step, q);
    }
    r.check(q.cx == INT32_MAX && q.cy == INT32_MIN, "demodulator saturates at the rails");
    r.digest_word(q.sx);
    r.digest_word(q.sy);
  }
}

void chain_on_synthetic_blocks(Report& r) {
  ChainConfig cfg;
  cfg.f_center_hz = 5000.5;
  static Chain<q31_t> chain(cfg);
  chain.reset();
  chain.set_excitation(true);
  std::array<q31_t, 2 * kL> adc{};
  std::array<q31_t, 3 * kL> dac{};
  const uint32_t step = phase_step_of_hz(5000.0, kFs);
  uint32_t gen_phase = 0;
  Lcg noise;
  for (int b = 0; b < 300; ++b) {
    make_block(adc, gen_phase, step, 0x40000000, 0x08000000, 0x40000000u, 0x40000000u, noise);
    r.check(chain.process(adc, dac), "chain accepts a block");
    for (q31_t v : dac)
      r.digest_word(v);
  }
  const ChainOutputs& o = chain.outputs();
  // a_A = sqrt(0.5^2 + 0.0625^2) FS = 0.5039 FS = 1.0078 V at 2 V full scale
  r.figure("chain a_A (uV)", static_cast<int64_t>(o.wave.a_A_v * 1e6));
  r.figure("chain PLL offset from 5 kHz (uHz)",
           static_cast<int64_t>((o.pll_freq_hz - 5000.0) * 1e6));
  r.check(std::fabs(o.wave.a_A_v - 2.0 * std::sqrt(0.25 + 0.0625 * 0.0625)) < 1e-4,
          "chain measures a_A");
  r.check(std::fabs(o.pll_freq_hz - 5000.0) < 1e-3, "chain PLL locks to the tone");
  chain.set_excitation(false);
  chain.process(adc, dac);
  bool zero = true;
  for (q31_t v : dac)
    zero = zero && v == 0;
  r.check(zero, "chain drives exactly zero with excitation off");
}

// The electronics corrections (dsp/pickoff_correction.hpp) on pseudo-random
// quadratures and at the rails. Coefficients are given as words (no libm),
// so both platforms run the same bits; every output goes into the digest.
void electronics_corrections(Report& r) {
  // g = 0.01, phase 1 deg, misalignment 0.5 deg; feedthrough ~1e-3 V/V
  // (scaled by 10 V / 2 V); and the -2 extremes.
  const PickoffCorrectionQ30 k{1063110717, 18556667, -18742233};
  const PickoffCorrectionQ30 worst{INT32_MIN, INT32_MIN, INT32_MIN};
  const FeedthroughCoefficients<q31_t> ft{9298604, 5368709, -2684355, 4649302};
  Lcg noise;
  int saturated = 0;
  for (int i = 0; i < 2000; ++i) {
    QuadSample<q31_t> q{noise.next(0x3FFFFFFF), noise.next(0x3FFFFFFF), noise.next(0x3FFFFFFF),
                        noise.next(0x3FFFFFFF)};
    const q31_t pump_re = noise.next(0x7FFFFFFF);  // sequenced: argument order is unspecified
    const q31_t pump_im = noise.next(0x7FFFFFFF);
    saturated += remove_feedthrough_q31(ft, pump_re, pump_im, q);
    saturated += correct_pickoffs_q31(k, q);
    r.digest_word(q.cx);
    r.digest_word(q.sx);
    r.digest_word(q.cy);
    r.digest_word(q.sy);
  }
  r.check(saturated == 0, "corrections of half-scale quadratures do not saturate");
  const std::array<q31_t, 6> rails{INT32_MIN, INT32_MIN + 1, -1, 0, 1, INT32_MAX};
  for (q31_t v : rails) {
    QuadSample<q31_t> q{v, v, v, v};
    const bool sat = correct_pickoffs_q31(worst, q);
    remove_feedthrough_q31({INT32_MIN, INT32_MIN, INT32_MIN, INT32_MIN}, v, v, q);
    r.digest_word(q.cy);
    r.digest_word(q.sy);
    r.digest_word(q.cx);
    r.digest_word(q.sx);
    r.check(sat == (v == INT32_MIN || v == INT32_MAX || v == INT32_MIN + 1),
            "pickoff correction saturates at the rails only");
  }
}

}  // namespace

int run_fixed_suite(Report& r) {
  helpers_at_the_rails(r);
  demodulator_at_the_rails(r);
  sine_within_its_bound(r);
  nco_wraps(r);
  demodulator_matches_reference(r);
  chain_on_synthetic_blocks(r);
  electronics_corrections(r);
  r.figure("checks", r.checks());
  r.figure("failures", r.failures());
  r.text("digest: ");
  r.hex64(r.digest());
  r.text("\n");
  return r.failures();
}

}  // namespace hrg::m7
