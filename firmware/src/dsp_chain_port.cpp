// SPDX-License-Identifier: MIT
#include "firmware/dsp_chain_port.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hrg::fw {

namespace {
constexpr double kPi = std::numbers::pi;
}  // namespace

dsp::ChainConfig chain_config_for(const ConverterLayout& conv, dsp::ChainConfig base) {
  base.sample_rate_hz = conv.sample_rate_hz;
  base.block_frames = conv.block_frames;
  base.adc_full_scale_v = conv.adc_full_scale_v;
  base.dac_full_scale_v = conv.dac_full_scale_v;
  base.dac_lead_frames = static_cast<double>(conv.block_frames) + 0.5 + conv.dac_latency_samples;
  return base;
}

ConverterLayout converter_layout(const hal::ConverterInfo& adc, const hal::ConverterInfo& dac,
                                 double dac_latency_samples) {
  ConverterLayout conv;
  conv.sample_rate_hz = static_cast<double>(adc.sample_rate_hz);
  conv.block_frames = adc.block_frames;
  conv.adc_full_scale_v = adc.full_scale_v;
  conv.dac_full_scale_v = dac.full_scale_v;
  conv.dac_latency_samples = dac_latency_samples;
  return conv;
}

double max_pattern_rate_rad_s(const dsp::ChainConfig& cfg, double margin) {
  const double w_rad_s = 2.0 * kPi * cfg.f_center_hz;
  const double a_v = std::max(cfg.amplitude_setpoint_v, cfg.min_amplitude_v);
  if (!(w_rad_s > 0.0) || !(a_v > 0.0)) return 0.0;
  return margin * cfg.forcer_gain_per_s2 * cfg.forcer_max_v / (4.0 * w_rad_s * a_v);
}

DspChainPort::DspChainPort(const dsp::ChainConfig& cfg, double pattern_max_rate_rad_s)
    : error_(dsp::check_chain_config(cfg)), chain_(cfg), pattern_max_rate_rad_s_(0.0) {
  const double limit = max_pattern_rate_rad_s(cfg);
  pattern_max_rate_rad_s_ =
      pattern_max_rate_rad_s > 0.0 ? std::min(pattern_max_rate_rad_s, limit) : limit;
}

void DspChainPort::process(std::span<const hal::q31_t> adc, std::span<hal::q31_t> dac,
                           const ChainCommands& cmd, ChainRecord& out) {
  if (error_ == nullptr) {
    // Each drive separately: a mode may allow the forcers (ring-up, pattern
    // moves) without the pump, or the reverse.
    chain_.set_drive_enables(cmd.pump_on, cmd.forcers_on);
    (void)chain_.set_amplitude_setpoint_v(cmd.amplitude_set_v);
    chain_.set_pattern_command(cmd.pattern_control, cmd.pattern_target_rad,
                               pattern_max_rate_rad_s_);
  }
  if (error_ != nullptr || !chain_.process(adc, dac)) {
    // Unusable configuration (error() says why) or a size mismatch: drives
    // off, nothing measured.
    for (auto& w : dac)
      w = 0;
    out.locked = false;
    return;
  }
  static_cast<dsp::ChainOutputs&>(out) = chain_.outputs();
  out.nco_phase = chain_.nco_phase();
}

}  // namespace hrg::fw
