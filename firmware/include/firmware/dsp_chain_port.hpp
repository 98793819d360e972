// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>
#include <type_traits>

#include "dsp/chain.hpp"
#include "dsp/fixed.hpp"
#include "firmware/chain_and_identifier.hpp"

namespace hrg::fw {

static_assert(std::is_same_v<hal::q31_t, dsp::q31_t>,
              "the HAL's sample words are the chain's Q1.31 words");

// The converter layout as the chain must know it (from the board's HAL
// converter info and data sheet, or the simulated target's configuration).
struct ConverterLayout {
  double sample_rate_hz = 100000.0;
  uint32_t block_frames = 100;
  double adc_full_scale_v = 2.0;     // pickoff volts at Q1.31 full scale
  double dac_full_scale_v = 10.0;    // electrode volts at Q1.31 full scale
  double dac_latency_samples = 0.0;  // DAC pipeline, frames
};

// `base` with the converter fields filled in: the DAC block written after ADC
// block n acts one block later, plus half a frame of zero-order hold, plus
// the DAC's pipeline.
dsp::ChainConfig chain_config_for(const ConverterLayout& conv, dsp::ChainConfig base = {});
// The layout of the board's HAL converters (the DAC pipeline, which the HAL
// does not describe, from the board's data sheet).
ConverterLayout converter_layout(const hal::ConverterInfo& adc, const hal::ConverterInfo& dac,
                                 double dac_latency_samples);

// Fastest pattern turn the forcers can make at the set point (rad/s of
// theta_A): theta_A' = g u_r / (4 w a_A) with u_r at forcer_max_v, less
// `margin` for the quadrature loop that shares the forcers.
double max_pattern_rate_rad_s(const dsp::ChainConfig& cfg, double margin = 0.8);

// The firmware's SignalChain over dsp::Chain: the mode policy gates the pump
// and the forcers separately, the pattern command steers theta_A (at no more
// than the forcers can do), and the chain's outputs are stamped into the record.
// The fast path is Q1.31 (bit-exact with the Cortex-M7 build).
class DspChainPort final : public SignalChain {
 public:
  using Sample = dsp::q31_t;

  // `cfg` is checked with dsp::check_chain_config: error() names the bad
  // field and process() then keeps the drives at zero. A non-positive
  // `pattern_max_rate_rad_s` takes the forcers' limit; a larger one is clamped to it.
  explicit DspChainPort(const dsp::ChainConfig& cfg, double pattern_max_rate_rad_s = 0.0);

  void process(std::span<const hal::q31_t> adc, std::span<hal::q31_t> dac, const ChainCommands& cmd,
               ChainRecord& out) override;

  bool usable() const { return error_ == nullptr; }
  // nullptr when usable, else the configuration error.
  const char* error() const { return error_; }
  const char* config_error() const override { return error_; }
  const dsp::Chain<Sample>& chain() const { return chain_; }
  // The electronics correction on the demodulated quadratures (see
  // dsp::Chain::set_electronics_correction); false leaves it unchanged.
  bool set_electronics_correction(const dsp::PickoffCorrection<double>& pickoff,
                                  const dsp::FeedthroughCoefficients<double>& feedthrough_v_per_v) {
    return chain_.set_electronics_correction(pickoff, feedthrough_v_per_v);
  }
  void clear_electronics_correction() { chain_.clear_electronics_correction(); }
  double pattern_max_rate_rad_s() const { return pattern_max_rate_rad_s_; }

 private:
  const char* error_;
  dsp::Chain<Sample> chain_;
  double pattern_max_rate_rad_s_;
};

}  // namespace hrg::fw
