// SPDX-License-Identifier: MIT
#include "dsp/pickoff_correction.hpp"

#include <cmath>
#include <numbers>

namespace hrg::dsp {

bool pickoff_correction_of(const PickoffMap& map, PickoffCorrection<double>& out) {
  const double g = map.y_gain;
  const double phi = map.y_phase_rad;
  const double b = map.y_misalignment_rad;
  if (!(std::isfinite(g) && std::isfinite(phi) && std::isfinite(b))) return false;
  if (!(1.0 + g > 0.0) || !(std::fabs(b) < std::numbers::pi / 4.0)) return false;
  const double c2b = std::cos(2.0 * b);
  const double scale = 1.0 / ((1.0 + g) * c2b);
  out.kc = std::cos(phi) * scale;
  out.ks = std::sin(phi) * scale;
  out.m = -std::tan(2.0 * b);
  return true;
}

namespace {

constexpr double kQ30One = 1073741824.0;  // 2^30

// double -> Q2.30, to nearest (ties away from zero); false outside [-2, 2 - 2^-30].
bool q30_of(double v, int32_t& out) {
  const double s = v * kQ30One;
  if (!(s >= -2147483648.0 && s <= 2147483647.0)) return false;
  const double r = s >= 0.0 ? std::floor(s + 0.5) : -std::floor(-s + 0.5);
  if (r > 2147483647.0) return false;
  out = static_cast<int32_t>(r);
  return true;
}

// a (Q1.31) x k (Q2.30) -> Q3.61 exact, then floor-shifted to Q5.59.
constexpr q63_t prod_q59(q31_t a, int32_t k) { return mul_q31_q63(a, k) >> 2; }

// Q5.59 -> Q1.31, to nearest (ties toward +inf), saturating.
constexpr q31_t q31_of_q59(q63_t v, bool& saturated) {
  const q63_t r = rshift_q63_rnd(v, 28);
  const q31_t s = sat_q63_to_q31(r);
  if (s != r) saturated = true;
  return s;
}

// Re or Im part of a complex product in Q1.31: (a b - c d) with each exact
// Q2.62 product floor-halved to Q3.61 first, then rounded once.
constexpr q63_t cross_q61(q31_t a, q31_t b, q31_t c, q31_t d) {
  return (mul_q31_q63(a, b) >> 1) - (mul_q31_q63(c, d) >> 1);
}

q31_t sub_sat(q31_t q, q63_t sub_q61, bool& saturated) {
  const q63_t r = static_cast<q63_t>(q) - rshift_q63_rnd(sub_q61, 30);
  const q31_t s = sat_q63_to_q31(r);
  if (s != r) saturated = true;
  return s;
}

}  // namespace

bool to_q30(const PickoffCorrection<double>& k, PickoffCorrectionQ30& out) {
  PickoffCorrectionQ30 q;
  if (!q30_of(k.kc, q.kc_q30) || !q30_of(k.ks, q.ks_q30) || !q30_of(k.m, q.m_q30)) return false;
  out = q;
  return true;
}

bool correct_pickoffs_q31(const PickoffCorrectionQ30& k, QuadSample<q31_t>& q) {
  bool saturated = false;
  const q63_t cy = prod_q59(q.cy, k.kc_q30) + prod_q59(q.sy, k.ks_q30) + prod_q59(q.cx, k.m_q30);
  const q63_t sy = prod_q59(q.sy, k.kc_q30) - prod_q59(q.cy, k.ks_q30) + prod_q59(q.sx, k.m_q30);
  q.cy = q31_of_q59(cy, saturated);
  q.sy = q31_of_q59(sy, saturated);
  return saturated;
}

bool remove_feedthrough_q31(const FeedthroughCoefficients<q31_t>& k, q31_t pump_re, q31_t pump_im,
                            QuadSample<q31_t>& q) {
  bool saturated = false;
  // X_ft = k P: Re = kr Pr - ki Pi, Im = kr Pi + ki Pr (the second as kr Pi - (-ki) Pr
  // would overflow for ki = INT32_MIN; written as a sum of halves instead).
  const q63_t x_re = cross_q61(k.x_re, pump_re, k.x_im, pump_im);
  const q63_t x_im = (mul_q31_q63(k.x_re, pump_im) >> 1) + (mul_q31_q63(k.x_im, pump_re) >> 1);
  const q63_t y_re = cross_q61(k.y_re, pump_re, k.y_im, pump_im);
  const q63_t y_im = (mul_q31_q63(k.y_re, pump_im) >> 1) + (mul_q31_q63(k.y_im, pump_re) >> 1);
  q.cx = sub_sat(q.cx, x_re, saturated);
  q.sx = sub_sat(q.sx, -x_im, saturated);
  q.cy = sub_sat(q.cy, y_re, saturated);
  q.sy = sub_sat(q.sy, -y_im, saturated);
  return saturated;
}

bool feedthrough_to_q31(const FeedthroughCoefficients<double>& k_v_per_v, double adc_full_scale_v,
                        double dac_full_scale_v, FeedthroughCoefficients<q31_t>& out) {
  if (!(adc_full_scale_v > 0.0 && dac_full_scale_v > 0.0)) return false;
  const double scale = dac_full_scale_v / adc_full_scale_v;
  const double v[4] = {k_v_per_v.x_re * scale, k_v_per_v.x_im * scale, k_v_per_v.y_re * scale,
                       k_v_per_v.y_im * scale};
  for (double c : v) {
    if (!(std::fabs(c) < 1.0)) return false;
  }
  out = {q31_from_f64_sat(v[0]), q31_from_f64_sat(v[1]), q31_from_f64_sat(v[2]),
         q31_from_f64_sat(v[3])};
  return true;
}

PumpEnvelopeFilter::PumpEnvelopeFilter(uint32_t block_frames) {
  const int64_t l = block_frames > 0 ? static_cast<int64_t>(block_frames) : 1;
  const double norm = std::pow(static_cast<double>(l), static_cast<double>(kDecimatorOrder));
  for (uint32_t k = 0; k < kDecimatorOrder; ++k) {
    double sum = 0.0;
    for (int64_t r = 0; r < l; ++r)
      sum += static_cast<double>(DecimatorWeights::bspline(static_cast<int64_t>(k) * l + r, l));
    w_[k] = sum / norm;
  }
}

void PumpEnvelopeFilter::reset() {
  re_ = {};
  im_ = {};
}

void PumpEnvelopeFilter::push(double pump_re, double pump_im, double& out_re, double& out_im) {
  out_re = w_[0] * pump_re;
  out_im = w_[0] * pump_im;
  for (std::size_t k = 1; k < w_.size(); ++k) {
    out_re += w_[k] * re_[k - 1];
    out_im += w_[k] * im_[k - 1];
  }
  for (std::size_t i = re_.size() - 1; i > 0; --i) {
    re_[i] = re_[i - 1];
    im_[i] = im_[i - 1];
  }
  re_[0] = pump_re;
  im_[0] = pump_im;
}

}  // namespace hrg::dsp
