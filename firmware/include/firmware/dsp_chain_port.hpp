// SPDX-License-Identifier: MIT
#pragma once

#include <span>

#include "dsp/chain.hpp"
#include "dsp/fixed.hpp"
#include "firmware/ports.hpp"

namespace hrg::fw {

// The firmware's SignalChain over dsp::Chain: the mode policy switches the
// chain's excitation (pump and forcers together), the pattern command steers
// theta_A, and the chain's slow outputs become ChainOutputs. The fast path is
// Q1.31 (bit-exact with the Cortex-M7 build).
class DspChainPort final : public SignalChain {
 public:
  using Sample = dsp::q31_t;

  // `cfg` must pass dsp::check_chain_config (usable() tells).
  explicit DspChainPort(const dsp::ChainConfig& cfg, double pattern_max_rate_rad_s = 0.5)
      : chain_(cfg), pattern_max_rate_rad_s_(pattern_max_rate_rad_s) {}

  void process(std::span<const hal::sample_q31> adc, std::span<hal::sample_q31> dac,
               const ChainCommands& cmd, ChainOutputs& out) override;

  bool usable() const { return dsp::check_chain_config(chain_.config()) == nullptr; }
  const dsp::Chain<Sample>& chain() const { return chain_; }

 private:
  dsp::Chain<Sample> chain_;
  double pattern_max_rate_rad_s_;
};

}  // namespace hrg::fw
