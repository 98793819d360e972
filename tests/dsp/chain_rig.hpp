// SPDX-License-Identifier: MIT
#pragma once

// Closed-loop rig: the full-rate simulated resonator (sim_target) between the
// chain's DAC and ADC blocks. Timing as a double-buffered converter pair: the
// ADC samples x, y at frame k, then the resonator advances one frame with
// the DAC word of frame k held (zero-order hold); the DAC block the chain
// writes after ADC block n is played during block n + 1. That is the chain's
// default dac_lead_frames = L + 0.5.

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "dsp/chain.hpp"
#include "dsp/fixed.hpp"
#include "sim_target/resonator.hpp"

namespace hrg::dsp::test {

inline constexpr double kAdcFullScaleV = 2.0;
inline constexpr double kDacFullScaleV = 10.0;

inline ChainConfig rig_config() {
  ChainConfig c;
  c.adc_full_scale_v = kAdcFullScaleV;
  c.dac_full_scale_v = kDacFullScaleV;
  c.pump_max_v = 10.0;
  c.forcer_max_v = 5.0;
  return c;
}

template <typename T>
class ChainRig {
 public:
  explicit ChainRig(const ChainConfig& cfg, const sim::ResonatorParams& rp = {},
                    const sim::ElectrodeParams& ep = {}, const sim::Effects& fx = {})
      : cfg_(cfg), res_(rp, ep, fx), chain_(cfg), l_(cfg.block_frames) {
    adc_.assign(2 * l_, 0);
    dac_now_.assign(3 * l_, 0);
    dac_next_.assign(3 * l_, 0);
  }

  sim::Resonator& resonator() { return res_; }
  // White Gaussian pickoff noise (V rms per sample, both channels), seeded.
  void set_pickoff_noise(double rms_v, uint64_t seed) {
    noise_rms_v_ = rms_v;
    rng_.seed(seed);
  }
  Chain<T>& chain() { return chain_; }
  const ChainOutputs& out() const { return chain_.outputs(); }
  // The ADC block of the last block() (for chains observing the same data).
  const std::vector<q31_t>& last_adc() const { return adc_; }
  double time_s() const { return res_.time_s(); }

  // One block: sample and advance the resonator L frames, then run the chain.
  void block() {
    const double dt = 1.0 / cfg_.sample_rate_hz;
    for (uint32_t j = 0; j < l_; ++j) {
      const sim::PickoffOutput p = res_.measured();
      const double nx = noise_rms_v_ > 0.0 ? noise_rms_v_ * gauss_(rng_) : 0.0;
      const double ny = noise_rms_v_ > 0.0 ? noise_rms_v_ * gauss_(rng_) : 0.0;
      adc_[2 * j] = q31_from_f64_sat((p.x_v + nx) / kAdcFullScaleV);
      adc_[2 * j + 1] = q31_from_f64_sat((p.y_v + ny) / kAdcFullScaleV);
      sim::Drive d;
      d.pump_v = f64_from_q31(dac_now_[3 * j]) * kDacFullScaleV;
      d.forcer_x_v = f64_from_q31(dac_now_[3 * j + 1]) * kDacFullScaleV;
      d.forcer_y_v = f64_from_q31(dac_now_[3 * j + 2]) * kDacFullScaleV;
      res_.step(d, dt);
    }
    chain_.process(adc_, dac_next_);
    dac_now_.swap(dac_next_);
  }

  // Runs for t_s seconds (whole blocks), calling fn() after every block.
  template <typename Fn>
  void run(double t_s, Fn fn) {
    const auto n = static_cast<long>(std::lround(t_s * cfg_.sample_rate_hz / l_));
    for (long k = 0; k < n; ++k) {
      block();
      fn();
    }
  }
  void run(double t_s) {
    run(t_s, [] {});
  }

 private:
  ChainConfig cfg_;
  sim::Resonator res_;
  Chain<T> chain_;
  uint32_t l_;
  std::vector<q31_t> adc_;
  std::vector<q31_t> dac_now_;
  std::vector<q31_t> dac_next_;
  double noise_rms_v_ = 0.0;
  std::mt19937_64 rng_{1};
  std::normal_distribution<double> gauss_{0.0, 1.0};
};

}  // namespace hrg::dsp::test
