// SPDX-License-Identifier: MIT
#include "dsp/electronics_correction.hpp"

namespace hrg::dsp {

template <typename T>
bool ElectronicsCorrection<T>::configure(const PickoffCorrection<double>& pickoff,
                                         const FeedthroughCoefficients<double>& feedthrough_v_per_v,
                                         double adc_full_scale_v, double dac_full_scale_v) {
  if (!(adc_full_scale_v > 0.0 && dac_full_scale_v > 0.0)) return false;
  const FeedthroughCoefficients<double>& k = feedthrough_v_per_v;
  Coefs p{};
  FeedthroughCoefficients<T> f{};
  if constexpr (std::is_same_v<T, q31_t>) {
    if (!to_q30(pickoff, p)) return false;
    if (!feedthrough_to_q31(k, adc_full_scale_v, dac_full_scale_v, f)) return false;
  } else {
    p = {static_cast<T>(pickoff.kc), static_cast<T>(pickoff.ks), static_cast<T>(pickoff.m)};
    const double s = dac_full_scale_v / adc_full_scale_v;  // FS of ADC per FS of DAC
    f = {static_cast<T>(k.x_re * s), static_cast<T>(k.x_im * s), static_cast<T>(k.y_re * s),
         static_cast<T>(k.y_im * s)};
  }
  pickoff_ = p;
  feedthrough_ = f;
  has_feedthrough_ = k.x_re != 0.0 || k.x_im != 0.0 || k.y_re != 0.0 || k.y_im != 0.0;
  inv_dac_fs_ = 1.0 / dac_full_scale_v;
  active_ = true;
  return true;
}

template <typename T>
void ElectronicsCorrection<T>::apply(double seen_re_v, double seen_im_v, QuadSample<T>& q) {
  if (!active_) return;
  bool saturated = false;
  if (has_feedthrough_) {
    const double re = seen_re_v * inv_dac_fs_;
    const double im = seen_im_v * inv_dac_fs_;
    if constexpr (std::is_same_v<T, q31_t>) {
      saturated |=
          remove_feedthrough_q31(feedthrough_, q31_from_f64_sat(re), q31_from_f64_sat(im), q);
    } else {
      remove_feedthrough(feedthrough_, static_cast<T>(re), static_cast<T>(im), q);
    }
  }
  if constexpr (std::is_same_v<T, q31_t>) {
    saturated |= correct_pickoffs_q31(pickoff_, q);
  } else {
    correct_pickoffs(pickoff_, q);
  }
  if (saturated) ++saturated_blocks_;
}

template class ElectronicsCorrection<q31_t>;
template class ElectronicsCorrection<float>;
template class ElectronicsCorrection<double>;

}  // namespace hrg::dsp
