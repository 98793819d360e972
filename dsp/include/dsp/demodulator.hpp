// SPDX-License-Identifier: MIT
#pragma once

// Two-channel quadrature demodulator with a decimating low-pass, one output
// per block (control rate = sample rate / block length).
//
//   cx = 2 <x cos wt>,  sx = 2 <x sin wt>,  cy = 2 <y cos wt>,  sy = 2 <y sin wt>
//
// wt is the NCO phase, so x = cx cos wt + sx sin wt (dsp/wave_variables.hpp).
//
// Low-pass: the cascade of N = kDecimatorOrder = 5 boxcars, each one block
// (L samples) long: a sinc^5 / fifth-order CIC response, N (L - 1) + 1 taps,
// linear phase, decimated by L. The NCO follows the resonance, so the mixing
// products hold the wave at DC and its image at 2f. Whatever 2f is, the image
// is rejected by at least N * 20 log10(L sin(pi 2f / fs)) dB (the envelope of
// the response, |sin(pi f L / fs)| <= 1): >= 100 dB for every resonance in
// decimator_band() (1594 Hz to 48.4 kHz for L = 100 at 100 kHz), with no rule
// tying the block to the resonance's period.
// - Passband droop: N 20 log10 |sin(pi f L / fs) / (L sin(pi f / fs))|, i.e.
//   -7.1e-3 dB at 10 Hz, -0.18 dB at 50 Hz for L = 100 at 100 kHz.
// - Group delay: decimator_group_delay_samples() = N (L - 1) / 2 samples before
//   the block's last sample (247.5 samples, 2.475 ms for L = 100 at 100 kHz),
//   the same at every frequency; an output describes the envelope there.
//
// Implementation: within a block N running sums A0 += u, A1 += A0, ...
// give the block's N binomial moments m_j = sum C(r + j, j) u_r (r samples
// before the block end); the block's share of the current and the next N - 1
// outputs is an integer combination of them (DecimatorWeights), the weights
// of the discrete B-spline being integer-valued polynomials of r. The sums
// restart every block, so fixed point never wraps and floating point never
// drifts. Cost per frame: 4 mixing products and 4 N additions for both
// channels; the combination is once per block.
//
// Contract of process_block (per type):
// - Input scaling: interleaved Q1.31 frames [x0, y0, x1, y1, ...], 1.0 = ADC
//   full scale; outputs in the same units (|c|, |s| <= 1).
// - Q1.31: each mixing product is rounded to nearest (ties up) at
//   2^-(31 - h), h = headroom_bits() the smallest shift >= 1 with L^N <= 2^(31 + h)
//   (h = 3 for L = 100), so every moment and the filter sum stay below 2^62:
//   no overflow anywhere for any input, the block combination is exact
//   (modulo 2^64 arithmetic whose true result is in range). The output
//   2 * sum * 2^h / L^N is rounded once to nearest (ties away from zero) and
//   saturates (reachable only for a square wave at the rails). The output is
//   within 2^h + 1/2 LSB of the exact filter of the exact products (the
//   filter doubles the products' rounding error of at most 2^(h-1) LSB).
// - Float: running sums in float within a block (L additions), the block
//   combination and the carries in double; double: all double. No overflow.

#include <array>
#include <numbers>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

#include "dsp/fixed.hpp"
#include "dsp/nco.hpp"
#include "dsp/sample.hpp"

namespace hrg::dsp {

inline constexpr uint32_t kDecimatorOrder = 5;
inline constexpr uint32_t kMinBlockFrames = 4;
inline constexpr uint32_t kMaxBlockFrames = 2000;
// The image rejection the chain guarantees, dB.
inline constexpr double kImageRejectionDb = 100.0;

// Quadratures in the sample type (Q1.31 or float/double).
template <typename T>
struct QuadSample {
  T cx{};
  T sx{};
  T cy{};
  T sy{};
};

// Delay of the decimating filter, samples: its output at the end of a block
// describes the envelope N (L - 1) / 2 samples before the block's last
// sample (the centre of its window). Telemetry time stamps use this.
constexpr double decimator_group_delay_samples(uint32_t block_frames) {
  return kDecimatorOrder * (static_cast<double>(block_frames) - 1.0) / 2.0;
}

// White input noise leaves successive outputs correlated (their windows,
// N blocks long, overlap): sum over lags m of rho(m), the factor by which a
// smooth combination of many outputs (a line through them, a mean) varies
// more than if they were independent. Exact for the discrete filter h =
// boxcar_L^N: its L polyphase sums are each L^(N-1), so sum_m R(mL) =
// L^(2N-1), over R(0) = sum h^2 (the central coefficient of boxcar_L^(2N),
// by inclusion-exclusion). 2.3233 for L = 100 (1 / B_10(0) = 2.3233 as L
// grows); 1 for L = 1.
inline double decimator_row_noise_correlation(uint32_t block_frames) {
  const double l = static_cast<double>(block_frames);
  const int n2 = 2 * static_cast<int>(kDecimatorOrder);
  const auto choose = [](double a, int b) {
    double c = 1.0;
    for (int i = 1; i <= b; ++i)
      c *= (a - b + i) / i;
    return c;
  };
  const double m = kDecimatorOrder * (l - 1.0);
  double sum_sq = 0.0;
  double sign = 1.0;
  for (int k = 0; k <= n2 && m - k * l >= 0.0; ++k, sign = -sign)
    sum_sq += sign * choose(n2, k) * choose(m - k * l + n2 - 1.0, n2 - 1);
  return std::pow(l, n2 - 1) / sum_sq;
}

// |H(f)| of the decimating filter in dB (<= 0) at input frequency f_hz:
// 20 N log10 |sin(pi f L / fs) / (L sin(pi f / fs))|. For the 2f image pass
// f = 2 f_resonance.
inline double image_rejection_db(double f_hz, double fs_hz, uint32_t block_frames) {
  const double pi = std::numbers::pi;
  const double l = static_cast<double>(block_frames);
  const double den = l * std::sin(pi * f_hz / fs_hz);
  if (den == 0.0) return 0.0;
  const double h = std::fabs(std::sin(pi * f_hz * l / fs_hz) / den);
  return h > 0.0 ? 20.0 * kDecimatorOrder * std::log10(h) : -400.0;
}

// Resonance band [lo_hz, hi_hz] over which the 2f image is >= 100 dB down
// for any frequency: the envelope bound N 20 log10(L |sin(pi 2f / fs)|) >= 100
// dB, i.e. |sin(pi 2f / fs)| >= 10^(5/N) / L. Empty (lo > hi) when L is too
// short for it.
struct DecimatorBand {
  double lo_hz = 0.0;
  double hi_hz = 0.0;
};
inline DecimatorBand decimator_band(double fs_hz, uint32_t block_frames) {
  const double pi = 3.14159265358979323846;
  const double need = std::pow(10.0, kImageRejectionDb / (20.0 * kDecimatorOrder)) /
                      static_cast<double>(block_frames);
  if (need >= 1.0) return DecimatorBand{fs_hz / 4.0, 0.0};
  const double a = std::asin(need) / pi;  // 2f / fs >= a and <= 1 - a
  return DecimatorBand{a * fs_hz / 2.0, (1.0 - a) * fs_hz / 2.0};
}

// Integer weights of the sinc^N decimator on the block moments: the share of
// a block in the output k blocks later is sum_j c[k][j] m_j (k, j < N).
// Built from the discrete B-spline b(n) = #{n = s_1 + .. + s_N, 0 <= s_i < L}:
// the weight of the sample r before the block end for lag k is b(k L + r), a
// polynomial of degree N - 1 in r; its coefficients on the basis C(r + j, j)
// follow from its values at r = 0..N-1 (forward differences, then the
// inverse of the unit upper triangle C(j, i)), all in exact integers.
struct DecimatorWeights {
  static constexpr uint32_t kN = kDecimatorOrder;
  std::array<std::array<int64_t, kN>, kN> c{};

  static constexpr int64_t binom(int64_t n, int64_t k) {
    if (k < 0 || n < k) return 0;
    int64_t r = 1;
    for (int64_t i = 1; i <= k; ++i)
      r = r * (n - k + i) / i;  // exact: r * (n - k + i) is i C(n - k + i, i)
    return r;
  }
  static constexpr int64_t bspline(int64_t n, int64_t l) {
    int64_t sum = 0;
    for (int64_t i = 0; i <= kN; ++i) {
      const int64_t t = binom(kN, i) * binom(n - i * l + kN - 1, kN - 1);
      sum += (i % 2 == 0) ? t : -t;
    }
    return sum;
  }
  explicit constexpr DecimatorWeights(uint32_t l) {
    for (uint32_t k = 0; k < kN; ++k) {
      std::array<int64_t, kN> d{};  // forward differences at r = 0
      for (uint32_t r = 0; r < kN; ++r)
        d[r] = bspline(static_cast<int64_t>(k) * l + r, l);
      for (uint32_t i = 1; i < kN; ++i)
        for (uint32_t r = kN - 1; r >= i; --r)
          d[r] -= d[r - 1];
      for (uint32_t i = kN; i-- > 0;) {  // back substitution, C(j, i) upper
        int64_t v = d[i];
        for (uint32_t j = i + 1; j < kN; ++j)
          v -= binom(j, i) * c[k][j];
        c[k][i] = v;
      }
    }
  }
};

template <typename T>
class Demodulator {
 public:
  using Ops = SampleOps<T>;
  static constexpr std::size_t kQuads = 4;  // cx, sx, cy, sy
  static constexpr uint32_t kN = kDecimatorOrder;
  // Running sums within a block; block combination and carries.
  using sum_t = typename Ops::acc_t;
  using comb_t = std::conditional_t<Ops::kFixed, q63_t, double>;
  // 16-byte vectors: 4 float lanes, or 2 lanes of q63/double (two vectors).
  static constexpr std::size_t kLanes = 16 / sizeof(sum_t);
  static constexpr std::size_t kVecs = kQuads / kLanes;
  typedef sum_t vec_t __attribute__((vector_size(16)));

  // block_frames: L, frames per block and decimation ratio,
  // kMinBlockFrames..kMaxBlockFrames (the chain checks it; others clamp).
  explicit Demodulator(uint32_t block_frames)
      : l_(clamp_l(block_frames)), h_(headroom_bits(l_)), w_(l_) {
    uint64_t p = 1;
    for (uint32_t i = 0; i < kN; ++i)
      p *= l_;
    ln_ = p;
    while (chunk_bits_ < 62 && (p >> (62 - chunk_bits_)) == 0)
      ++chunk_bits_;
  }

  uint32_t block_frames() const { return l_; }

  // Q1.31 headroom shift h: the smallest h >= 1 with L^N <= 2^(31 + h).
  static constexpr int headroom_bits(uint32_t l) {
    uint64_t p = 1;
    for (uint32_t i = 0; i < kN; ++i)
      p *= l;
    int h = 1;  // at least 1: the product's high word then carries the result
    while (p > (uint64_t{1} << (31 + h)))
      ++h;
    return h;
  }
  int headroom_bits() const { return h_; }

  // Clears the filter history (outputs restart from zero input).
  void reset() {
    for (auto& c : carry_)
      c.fill(comb_t{});
  }

  // Mixes one block with the NCO starting at `phase` (advanced by `step` per
  // frame; updated to the phase after the block) and returns the filter output
  // at the block's end. `frames` must hold 2 * block_frames() words; a wrong
  // size returns false and leaves everything unchanged. Task context, once
  // per block; no allocation.
  bool process_block(std::span<const q31_t> frames, uint32_t& phase, uint32_t step,
                     QuadSample<T>& out) {
    if (frames.size() != 2u * l_) return false;
    // The four quadratures side by side (SIMD lanes where the target has
    // them, plain scalars where not: same arithmetic, same bits).
    static_assert(kN == 5, "the running sums below are written out for N = 5");
    vec_t a0[kVecs] = {}, a1[kVecs] = {}, a2[kVecs] = {}, a3[kVecs] = {}, a4[kVecs] = {};
    const q31_t* p = frames.data();
    uint32_t ph = phase;
    const int shift = 31 + h_;
    for (uint32_t n = 0; n < l_; ++n) {
      const T x = Ops::from_q31(p[2 * n]);
      const T y = Ops::from_q31(p[2 * n + 1]);
      T c, s;
      sincos_turns<T>(ph, c, s);
      ph += step;
      const sum_t u[kQuads] = {mix(x, c, shift), mix(x, s, shift), mix(y, c, shift),
                               mix(y, s, shift)};
      for (std::size_t v = 0; v < kVecs; ++v) {
        vec_t uv;
        for (std::size_t i = 0; i < kLanes; ++i)
          uv[i] = u[v * kLanes + i];
        a0[v] += uv;
        a1[v] += a0[v];
        a2[v] += a1[v];
        a3[v] += a2[v];
        a4[v] += a3[v];
      }
    }
    sum_t a[kN][kQuads];
    for (std::size_t q = 0; q < kQuads; ++q) {
      a[0][q] = a0[q / kLanes][q % kLanes];
      a[1][q] = a1[q / kLanes][q % kLanes];
      a[2][q] = a2[q / kLanes][q % kLanes];
      a[3][q] = a3[q / kLanes][q % kLanes];
      a[4][q] = a4[q / kLanes][q % kLanes];
    }
    phase = ph;
    comb_t now[kQuads];
    combine(a, now);
    out = QuadSample<T>{finish(now[0]), finish(now[1]), finish(now[2]), finish(now[3])};
    return true;
  }

 private:
  static uint32_t clamp_l(uint32_t l) {
    return l < kMinBlockFrames ? kMinBlockFrames : (l > kMaxBlockFrames ? kMaxBlockFrames : l);
  }

  HRG_DSP_INLINE static sum_t mix(T x, T ref, int shift) {
    if constexpr (Ops::kFixed) {
      // shift = 32 + (h - 1) >= 32: round, then keep the high word and shift
      // it; the result has |u| <= 2^30 (a 32-bit core needs no 64-bit shift).
      const q63_t p = mul_q31_q63(x, ref) + (q63_t{1} << (shift - 1));
      return static_cast<int32_t>(p >> 32) >> (shift - 32);
    } else {
      (void)shift;
      return Ops::mix(x, ref);
    }
  }

  // The block's share of this and the next N - 1 outputs, for all four
  // quadratures; returns this output's filter sums. The share now is the top
  // moment (the weights of the newest block are C(r + N - 1, N - 1)).
  // Fixed point: modulo 2^64 (the true values are below 2^62, so exact).
  void combine(const sum_t (&a)[kN][kQuads], comb_t (&now)[kQuads]) {
    using mac_t = std::conditional_t<Ops::kFixed, uint64_t, double>;
    for (std::size_t q = 0; q < kQuads; ++q)
      now[q] = static_cast<comb_t>(a[kN - 1][q]) + carry_[0][q];
    for (uint32_t k = 1; k < kN; ++k) {
      mac_t v[kQuads] = {};
      for (uint32_t j = 0; j < kN; ++j) {
        const auto c = static_cast<mac_t>(w_.c[k][j]);
        for (std::size_t q = 0; q < kQuads; ++q)
          v[q] += c * static_cast<mac_t>(a[j][q]);
      }
      for (std::size_t q = 0; q < kQuads; ++q)
        carry_[k - 1][q] = static_cast<comb_t>(v[q]) + (k + 1 < kN ? carry_[k][q] : comb_t{});
    }
  }

  // 2 sum / L^N (times 2^h in Q1.31) in the output type.
  T finish(comb_t sum) const {
    if constexpr (Ops::kFixed) {
      // |sum| <= L^N 2^(31-h) <= 2^62: long division with h + 1 extra
      // quotient bits (in chunks that cannot overflow), then round to
      // nearest, ties away from zero.
      const bool neg = sum < 0;
      const uint64_t mag = neg ? static_cast<uint64_t>(-sum) : static_cast<uint64_t>(sum);
      uint64_t quo = mag / ln_;
      uint64_t rem = mag % ln_;
      for (int left = h_ + 1; left > 0;) {  // rem << k stays below 2^63
        const int k = left < chunk_bits_ ? left : chunk_bits_;
        rem <<= k;
        quo = (quo << k) + rem / ln_;
        rem %= ln_;
        left -= k;
      }
      if (2 * rem >= ln_) ++quo;
      const q63_t v = static_cast<q63_t>(quo);
      return sat_q63_to_q31(neg ? -v : v);
    } else {
      return static_cast<T>(2.0 * sum / static_cast<double>(ln_));
    }
  }

  uint32_t l_;
  int h_;
  DecimatorWeights w_;
  uint64_t ln_ = 1;     // L^N
  int chunk_bits_ = 1;  // largest k with L^N 2^k < 2^63
  std::array<std::array<comb_t, kQuads>, kN - 1> carry_{};
};

}  // namespace hrg::dsp
