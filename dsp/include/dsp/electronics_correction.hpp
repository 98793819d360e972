// SPDX-License-Identifier: MIT
#pragma once

// The chain's electronics-correction stage: on each block's demodulated
// quadratures, before the wave variables, the drive feedthrough is removed
// (using the pump envelope that acted during that ADC block, through
// PumpEnvelopeFilter so the switching instants are right too) and then the
// pickoff map is inverted (dsp/pickoff_correction.hpp for the kernels and
// their contracts). Q1.31 chain: the Q1.31 kernels (Q2.30 pickoff
// coefficients, Q1.31 feedthrough coefficients in ADC full scale per DAC full
// scale); float chains: the same arithmetic in full-scale units.
// Inactive (the default) it costs one branch per block. No heap.

#include <cstdint>
#include <type_traits>

#include "dsp/demodulator.hpp"
#include "dsp/fixed.hpp"
#include "dsp/pickoff_correction.hpp"

namespace hrg::dsp {

template <typename T>
class ElectronicsCorrection {
 public:
  explicit ElectronicsCorrection(uint32_t block_frames) : envelope_(block_frames) {}

  // Takes the correction; false (and the stage unchanged) when a coefficient
  // does not fit the chain's number format or a full scale is not positive.
  bool configure(const PickoffCorrection<double>& pickoff,
                 const FeedthroughCoefficients<double>& feedthrough_v_per_v,
                 double adc_full_scale_v, double dac_full_scale_v);
  // Back to the identity (nothing corrected).
  void clear() {
    active_ = false;
    envelope_.reset();
  }
  // Forgets the pump history (chain reset).
  void reset() { envelope_.reset(); }
  bool active() const { return active_; }

  // `pump_re_v, pump_im_v`: the pump envelope (volts, against the NCO) that
  // acted during the ADC block `q` was demodulated from (zero while off).
  void apply(double pump_re_v, double pump_im_v, QuadSample<T>& q);

  // Blocks where a corrected quadrature saturated (Q1.31 only).
  uint32_t saturated_blocks() const { return saturated_blocks_; }

 private:
  using Coefs =
      std::conditional_t<std::is_same_v<T, q31_t>, PickoffCorrectionQ30, PickoffCorrection<T>>;
  PumpEnvelopeFilter envelope_;
  Coefs pickoff_{};
  FeedthroughCoefficients<T> feedthrough_{};  // full scale per DAC full scale
  bool has_feedthrough_ = false;
  double inv_dac_fs_ = 0.1;
  bool active_ = false;
  uint32_t saturated_blocks_ = 0;
};

extern template class ElectronicsCorrection<q31_t>;
extern template class ElectronicsCorrection<float>;
extern template class ElectronicsCorrection<double>;

}  // namespace hrg::dsp
