// SPDX-License-Identifier: MIT
#pragma once

// Two-channel quadrature demodulator with a decimating low-pass, one output
// per block (control rate = sample rate / block length).
//
//   cx = 2 <x cos wt>,  sx = 2 <x sin wt>,  cy = 2 <y cos wt>,  sy = 2 <y sin wt>
//
// wt is the NCO phase, so x = cx cos wt + sx sin wt (dsp/wave_variables.hpp).
//
// Low-pass: the cascade of three boxcars, each one block (L samples) long
// (a sinc^3 / third-order CIC response, 3L - 2 taps, delay 1.5 L - 1 samples),
// decimated by L. Periodicity rule (seed, section 3: average "with control of
// periodicity for w: <cos wt sin wt> = 0"): the default block of 100 samples
// at 100 kHz spans exactly 5 periods of the 5 kHz resonance, so the 2f image
// of the mixing products falls on a zero of every boxcar. The resonance is
// not exactly at a multiple of fs / 2L and the PLL moves it; the third order
// keeps the image >= 100 dB down while 2f stays within +-231 Hz of a multiple
// of the output rate (resonance within +-115 Hz of the rule's frequency),
// see image_rejection_db().
//
// Implementation: within a block the three running sums A0 += u, A1 += A0,
// A2 += A1 give the three polynomial moments of the block, from which the
// block's contribution to the current and the two next outputs follows
// exactly (integer weights). The sums restart every block, so fixed point
// never wraps and floating point never drifts. Cost per frame: 4 mixing
// products and 12 additions for both channels.
//
// Contract of process_block (per type):
// - Input scaling: interleaved Q1.31 frames [x0, y0, x1, y1, ...], 1.0 = ADC
//   full scale; outputs in the same units (|c|, |s| <= 1).
// - Overflow: Q1.31 sums are q63 (need 31 + 3 log2(L) bits: L <= 2000), no
//   wrap; the final Q1.31 output saturates (reachable only for a square wave
//   at the rails). Float/double: none.
// - Rounding (Q1.31): each mixing product to nearest (ties up) at 2^-31, the
//   final division by L^3 to nearest (ties away from zero); the output is
//   within 1 LSB + 1 LSB of the exact filter of the rounded products.

#include <array>
#include <numbers>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "dsp/fixed.hpp"
#include "dsp/nco.hpp"
#include "dsp/sample.hpp"

namespace hrg::dsp {

// Quadratures in the sample type (Q1.31 or float/double).
template <typename T>
struct QuadSample {
  T cx{};
  T sx{};
  T cy{};
  T sy{};
};

// |H(f)| of the decimating filter in dB (<= 0) at input frequency f_hz:
// 20 log10 |sin(pi f L / fs) / (L sin(pi f / fs))|^3. For the 2f image pass
// f = 2 f_resonance.
inline double image_rejection_db(double f_hz, double fs_hz, uint32_t block_frames) {
  const double pi = std::numbers::pi;
  const double l = static_cast<double>(block_frames);
  const double den = l * std::sin(pi * f_hz / fs_hz);
  if (den == 0.0) return 0.0;
  const double h = std::fabs(std::sin(pi * f_hz * l / fs_hz) / den);
  return h > 0.0 ? 60.0 * std::log10(h) : -400.0;
}

template <typename T>
class Demodulator {
 public:
  using Ops = SampleOps<T>;
  using acc_t = typename Ops::acc_t;
  static constexpr std::size_t kQuads = 4;  // cx, sx, cy, sy

  // block_frames: L, frames per block and decimation ratio, 1..2000.
  explicit Demodulator(uint32_t block_frames) : l_(block_frames) {
    const acc_t l = static_cast<acc_t>(l_);
    l3_ = l * l * l;
    w2_const_ = l * (l - 1) / 2;
    l2_ = l * l;
  }

  uint32_t block_frames() const { return l_; }

  // Clears the filter history (outputs restart from zero input).
  void reset() {
    carry1_.fill(acc_t{});
    carry2_.fill(acc_t{});
  }

  // Mixes one block with the NCO starting at `phase` (advanced by `step` per
  // frame; updated to the phase after the block) and returns the filter output
  // at the block's end. `frames` must hold 2 * block_frames() words; a wrong
  // size returns false and leaves everything unchanged. Task context, once
  // per block; no allocation.
  bool process_block(std::span<const q31_t> frames, uint32_t& phase, uint32_t step,
                     QuadSample<T>& out) {
    if (frames.size() != 2u * l_) return false;
    // Running sums per quadrature: a0 = sum u, a1 = sum a0, a2 = sum a1.
    acc_t a0[kQuads] = {};
    acc_t a1[kQuads] = {};
    acc_t a2[kQuads] = {};
    const q31_t* p = frames.data();
    uint32_t ph = phase;
    for (uint32_t n = 0; n < l_; ++n) {
      const T x = Ops::from_q31(p[2 * n]);
      const T y = Ops::from_q31(p[2 * n + 1]);
      const T c = cos_turns<T>(ph);
      const T s = sin_turns<T>(ph);
      ph += step;
      const acc_t u[kQuads] = {Ops::mix(x, c), Ops::mix(x, s), Ops::mix(y, c), Ops::mix(y, s)};
      for (std::size_t k = 0; k < kQuads; ++k) {
        a0[k] += u[k];
        a1[k] += a0[k];
        a2[k] += a1[k];
      }
    }
    phase = ph;
    T o[kQuads];
    for (std::size_t k = 0; k < kQuads; ++k) {
      // Weights of sample i (r = L - 1 - i samples before the block end):
      // now (r+1)(r+2)/2, in two blocks (L-1-r)(L-2-r)/2, in one block the rest.
      const acc_t w0 = a2[k];
      const acc_t w2 = w2_const_ * a0[k] - l_acc() * a1[k] + a2[k];
      const acc_t w1 = l2_ * a0[k] - w0 - w2;
      const acc_t sum = w0 + carry1_[k];
      carry1_[k] = w1 + carry2_[k];
      carry2_[k] = w2;
      o[k] = finish(sum);
    }
    out = QuadSample<T>{o[0], o[1], o[2], o[3]};
    return true;
  }

 private:
  acc_t l_acc() const { return static_cast<acc_t>(l_); }

  // 2 * sum / L^3 in the output type.
  T finish(acc_t sum) const {
    if constexpr (Ops::kFixed) {
      return sat_q63_to_q31(div_q63_rnd(2 * sum, l3_));
    } else {
      return T(2) * sum / l3_;
    }
  }

  uint32_t l_;
  acc_t l3_{};
  acc_t l2_{};
  acc_t w2_const_{};
  std::array<acc_t, kQuads> carry1_{};
  std::array<acc_t, kQuads> carry2_{};
};

}  // namespace hrg::dsp
