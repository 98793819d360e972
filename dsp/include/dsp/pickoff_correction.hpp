// SPDX-License-Identifier: MIT
#pragma once

// Electronics corrections applied to the demodulated quadratures, before the
// wave variables (docs/effects-catalog.md, measurement side):
//
// 1. Drive feedthrough. While the pump runs each pickoff gains k V_pump with
//    a complex coefficient k = c e^{i psi} (V/V): in envelopes
//    X_meas = X + k_x P, Y_meas = Y + k_y P, with P the pump envelope
//    (pump = Re(P e^{iwt}), wt the NCO phase). It is removed first, because
//    it adds after the pickoff chain.
// 2. Pickoff map. The y chain sees the x pickoff through a misalignment b,
//    has a gain 1 + g and lags by phi:
//        X_meas = X,  Y_meas = (1 + g) e^{-i phi} (cos2b Y + sin2b X).
//    Its exact inverse, with X = cx - i sx and Y = cy - i sy
//    (dsp/wave_variables.hpp), is linear in the quadratures:
//        cy = kc cy_m + ks sy_m + m cx
//        sy = kc sy_m - ks cy_m + m sx
//    kc = cos phi / ((1+g) cos2b), ks = sin phi / ((1+g) cos2b), m = -tan 2b;
//    cx and sx pass unchanged.
//
// Float/double kernels: no scaling, no overflow below 1e30, IEEE rounding.
// Q1.31 kernels: see their contracts below. All of it: no heap, no
// exceptions, a fixed amount of work per call.

#include <array>
#include <cmath>
#include <cstdint>

#include "dsp/demodulator.hpp"
#include "dsp/fixed.hpp"
#include "dsp/wave_variables.hpp"

namespace hrg::dsp {

// The measured map (the catalogue's parameters, SI units).
struct PickoffMap {
  double y_gain = 0.0;              // g: y_meas = (1 + g) y (-)
  double y_phase_rad = 0.0;         // phi: Y_meas = Y e^{-i phi}, y lags x (rad)
  double y_misalignment_rad = 0.0;  // b, physical: y_meas = y cos2b + x sin2b (rad)
};

// Coefficients of the inverse map (dimensionless).
template <typename F>
struct PickoffCorrection {
  F kc{1};
  F ks{0};
  F m{0};
};

// Returns false (and leaves `out` unchanged) when the map has no inverse
// (1 + g <= 0, |b| >= 45 deg, or a non-finite parameter).
bool pickoff_correction_of(const PickoffMap& map, PickoffCorrection<double>& out);

// Applies the inverse map in place (Quadratures<F> or QuadSample<F>, F float/double).
template <typename F, template <typename> class Quad>
void correct_pickoffs(const PickoffCorrection<F>& k, Quad<F>& q) {
  const F cy = k.kc * q.cy + k.ks * q.sy + k.m * q.cx;
  const F sy = k.kc * q.sy - k.ks * q.cy + k.m * q.sx;
  q.cy = cy;
  q.sy = sy;
}

// Q2.30 coefficients: value = word / 2^30, range [-2, 2).
struct PickoffCorrectionQ30 {
  int32_t kc_q30 = int32_t{1} << 30;
  int32_t ks_q30 = 0;
  int32_t m_q30 = 0;
};

// Rounds to nearest (ties away from zero). Returns false (and leaves `out`
// unchanged) when a coefficient is outside [-2, 2 - 2^-30].
bool to_q30(const PickoffCorrection<double>& k, PickoffCorrectionQ30& out);

// Q1.31 kernel on the demodulator's output.
// - Scaling: quadratures Q1.31 (1.0 = ADC full scale), coefficients Q2.30.
// - Each product Q1.31 x Q2.30 is formed exactly in a q63 (Q3.61, |p| <= 2^62)
//   and shifted right by 2 (floor) before the three are summed, so the sum
//   stays below 3 * 2^60: no overflow for any inputs and coefficients.
// - Rounding: the Q5.59 sum to Q1.31 once, to nearest, ties toward +inf. The
//   result is within 0.5 LSB + 3 * 2^-28 LSB of the exact value.
// - Overflow of the result: saturates to [INT32_MIN, INT32_MAX]; the return
//   value says whether cy or sy saturated (the corrected signal left the
//   ADC's range: the caller counts it).
bool correct_pickoffs_q31(const PickoffCorrectionQ30& k, QuadSample<q31_t>& q);

// Drive feedthrough: k_x, k_y as complex coefficients per volt of pump (V/V).
template <typename F>
struct FeedthroughCoefficients {
  F x_re{0};
  F x_im{0};
  F y_re{0};
  F y_im{0};
};

// Removes k P from both channels; P = pump_re + i pump_im is the pump
// envelope the demodulator saw over the same window (volts, or the units of
// the quadratures times the coefficients' inverse). X_ft = k_x P appears as
// cx += Re(k_x P), sx -= Im(k_x P).
template <typename F, template <typename> class Quad>
void remove_feedthrough(const FeedthroughCoefficients<F>& k, F pump_re, F pump_im, Quad<F>& q) {
  q.cx -= k.x_re * pump_re - k.x_im * pump_im;
  q.sx += k.x_re * pump_im + k.x_im * pump_re;
  q.cy -= k.y_re * pump_re - k.y_im * pump_im;
  q.sy += k.y_re * pump_im + k.y_im * pump_re;
}

// Q1.31 form. Coefficients are Q1.31 in ADC full scale per DAC full scale
// (k_v_per_v * dac_full_scale_v / adc_full_scale_v, see feedthrough_to_q31);
// the pump envelope is Q1.31 of the DAC's full scale.
// - Each of the two products of a real or imaginary part is exact in a q63
//   (Q2.62, |p| <= 2^62), halved (floor) before the pair is summed: no
//   overflow for any input.
// - Rounding: the Q3.61 sum to Q1.31 once, to nearest, ties toward +inf
//   (within 0.5 LSB + 2^-30 LSB of the exact product of the Q1.31 words),
//   then a saturating subtraction from the quadrature. The coefficients'
//   own rounding adds up to 0.5 LSB x (|Re P| + |Im P|).
// - Returns whether any quadrature saturated.
bool remove_feedthrough_q31(const FeedthroughCoefficients<q31_t>& k, q31_t pump_re, q31_t pump_im,
                            QuadSample<q31_t>& q);

// Q1.31 coefficients from V/V ones. Rounding: to nearest. Returns false
// (and leaves `out` unchanged) when a scaled coefficient is not inside
// (-1, 1) or a full scale is not positive.
bool feedthrough_to_q31(const FeedthroughCoefficients<double>& k_v_per_v, double adc_full_scale_v,
                        double dac_full_scale_v, FeedthroughCoefficients<q31_t>& out);

// The pump envelope as the demodulator sees it. The sinc^3 decimator spreads
// each block over three outputs; for an envelope held constant over each
// block (the chain synthesises the pump at the NCO phase plus a per-block
// offset) the output at the end of block n is exactly
//     w0 P_n + w1 P_{n-1} + ... + w_{N-1} P_{n-N+1}   (N = kDecimatorOrder),
// w_k the sum of the cascade's integer weights over block n - k, over L^N
// (w0 = C(L+N-1, N) / L^N).
// Feeding it the envelope actually acting during each ADC block (zero while
// the pump is off) makes the removal right at the switching instants too,
// up to the 2f mixing product of the step, which the sinc^N nulls only for
// a steady envelope (1.6 % of the step in the test at the default block,
// for one block). In the chain the DAC block written after ADC block n acts
// from frame (n + 1) L + 0.5 (ChainConfig::dac_lead_frames): the envelope of
// ADC block n is the pump (V0, phase against the NCO) the chain synthesised
// one block earlier; the half frame is left out (0.5 % of a step).
class PumpEnvelopeFilter {
 public:
  explicit PumpEnvelopeFilter(uint32_t block_frames);
  void reset();
  // The pump envelope over the block just demodulated; returns the filtered
  // envelope matching that block's demodulator output.
  void push(double pump_re, double pump_im, double& out_re, double& out_im);
  std::array<double, kDecimatorOrder> weights() const { return w_; }

 private:
  std::array<double, kDecimatorOrder> w_{};
  std::array<double, kDecimatorOrder - 1> re_{};  // envelopes of the blocks before
  std::array<double, kDecimatorOrder - 1> im_{};
};

}  // namespace hrg::dsp
