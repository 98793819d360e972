// SPDX-License-Identifier: MIT
#include "firmware/dsp_chain_port.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hrg::fw {

namespace {
constexpr double kPi = std::numbers::pi;

double wrap_pi(double a) { return a - 2.0 * kPi * std::round(a / (2.0 * kPi)); }
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

void DspChainPort::process(std::span<const hal::sample_q31> adc, std::span<hal::sample_q31> dac,
                           const ChainCommands& cmd, ChainOutputs& out) {
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
    have_pump_phase_ = false;
    return;
  }
  const dsp::ChainOutputs& o = chain_.outputs();
  const dsp::ChainConfig& c = chain_.config();
  out.cx_v = o.quad.cx;
  out.sx_v = o.quad.sx;
  out.cy_v = o.quad.cy;
  out.sy_v = o.quad.sy;
  out.e_v2 = o.wave.E;
  out.a_a_v = o.wave.a_A;
  out.a_b_v = o.wave.a_B;
  out.theta_a_rad = o.theta_A_rad;  // unwrapped by the chain
  out.f_ref_hz = o.pll_freq_hz;
  out.pump_v = o.pump_v;
  out.quad_effort = c.forcer_max_v > 0.0 ? o.quad_effort_v / c.forcer_max_v : 0.0;
  // The pump acting during this block was set from the previous block's
  // wave phase; against the wave phase measured now its error is
  // eps = pi/2 - 2 (phi_V - phi_A), phi_V - phi_A ideally pump_phase_rad.
  // Only the phase offset away from the ideal quarter turn counts.
  if (have_pump_phase_ && o.pump_v > 0.0) {
    const double phi_a = o.pump_phase_rad - c.pump_phase_rad;  // this block's wave phase
    out.pump_phase_error_rad = wrap_pi(kPi / 2.0 - 2.0 * (last_pump_phase_rad_ - phi_a));
  } else {
    out.pump_phase_error_rad = 0.0;
  }
  last_pump_phase_rad_ = o.pump_phase_rad;
  have_pump_phase_ = true;
  // Forcer actions (chain.hpp): the quadrature drive u_q changes a_B at
  // g u_q / (2 w), synthesized in phase with wave A's displacement, so it
  // has no commanded part on the angle. The pattern drive is not a control
  // error (it turns the pattern on purpose, with the output held) and is
  // left out.
  const double w_rad_s = 2.0 * kPi * (o.pll_freq_hz > 0.0 ? o.pll_freq_hz : c.f_center_hz);
  out.quad_sin_v_s = c.forcer_gain_per_s2 / (2.0 * w_rad_s) * o.quad_effort_v;
  out.quad_cos_v_s = 0.0;
  out.locked = o.locked;
}

}  // namespace hrg::fw
