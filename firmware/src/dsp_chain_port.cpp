// SPDX-License-Identifier: MIT
#include "firmware/dsp_chain_port.hpp"

namespace hrg::fw {

void DspChainPort::process(std::span<const hal::sample_q31> adc, std::span<hal::sample_q31> dac,
                           const ChainCommands& cmd, ChainOutputs& out) {
  chain_.set_excitation(cmd.pump_on || cmd.forcers_on);
  chain_.set_amplitude_setpoint_v(cmd.amplitude_set_v);
  chain_.set_pattern_command(cmd.pattern_control, cmd.pattern_target_rad, pattern_max_rate_rad_s_);
  if (!chain_.process(adc, dac)) {
    // Size mismatch or unusable configuration: drives off, nothing measured.
    for (auto& w : dac)
      w = 0;
    out.locked = false;
    return;
  }
  const dsp::ChainOutputs& o = chain_.outputs();
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
  const double fmax = chain_.config().forcer_max_v;
  out.quad_effort = fmax > 0.0 ? o.quad_effort_v / fmax : 0.0;
  out.locked = o.locked;
}

}  // namespace hrg::fw
