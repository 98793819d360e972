// SPDX-License-Identifier: MIT
#pragma once

// The chain's electronics-correction stage: on each block's demodulated
// quadratures, before the wave variables, the drive feedthrough is removed
// (using the pump envelope as that block's demodulator output saw it, which
// the chain keeps through PumpEnvelopeFilter so the switching instants are
// right too) and then the
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
  // Takes the correction; false (and the stage unchanged) when a coefficient
  // does not fit the chain's number format or a full scale is not positive.
  bool configure(const PickoffCorrection<double>& pickoff,
                 const FeedthroughCoefficients<double>& feedthrough_v_per_v,
                 double adc_full_scale_v, double dac_full_scale_v);
  // Back to the identity (nothing corrected).
  void clear() { active_ = false; }
  bool active() const { return active_; }

  // `seen_re_v, seen_im_v`: the pump envelope (volts, against the NCO) as
  // the demodulator output `q` saw it (PumpEnvelopeFilter over the blocks
  // whose pump acted in its window; zero while off).
  void apply(double seen_re_v, double seen_im_v, QuadSample<T>& q);

  // Blocks where a corrected quadrature saturated (Q1.31 only).
  uint32_t saturated_blocks() const { return saturated_blocks_; }

 private:
  using Coefs =
      std::conditional_t<std::is_same_v<T, q31_t>, PickoffCorrectionQ30, PickoffCorrection<T>>;
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
