// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <cstdint>
#include <span>

#include "firmware/chain_and_identifier.hpp"

namespace hrg::fakes {

// An envelope-level stand-in for the DSP chain and the resonator behind it:
// a_A rises towards the set point at `ring_rate_v_per_block` while driven,
// decays by `decay_per_block` (relative) while the drives are off; theta_A
// turns at `theta_rate_rad_per_block` and moves towards a pattern target at
// `pattern_rate_rad_per_block`. Back door: lock, amplitude and rates.
// It writes a constant into every DAC word so the mode gate can be seen.
class FakeChain final : public fw::SignalChain {
 public:
  void process(std::span<const hal::q31_t>, std::span<hal::q31_t> dac, const fw::ChainCommands& cmd,
               fw::ChainRecord& out) override {
    ++calls_;
    last_cmd_ = cmd;
    for (auto& w : dac)
      w = 1000;
    const bool driven = cmd.pump_on || cmd.forcers_on;
    if (driven) {
      a_a_ += ring_rate_v_per_block;
      if (a_a_ > cmd.amplitude_set_v) a_a_ = cmd.amplitude_set_v;
    } else {
      a_a_ *= 1.0 - decay_per_block;
    }
    theta_ += theta_rate_rad_per_block;
    if (cmd.pattern_control) {
      const double err = cmd.pattern_target_rad - theta_;
      theta_ += std::fabs(err) < pattern_rate_rad_per_block
                    ? err
                    : std::copysign(pattern_rate_rad_per_block, err);
    }
    out.wave.a_A_v = a_a_;
    out.wave.a_B_v = 0.0;
    out.wave.E_v2 = a_a_ * a_a_;
    out.theta_A_rad = theta_;  // unwrapped, as the chain gives it
    out.locked = locked;
    out.pump_v = cmd.pump_on ? 3.0 : 0.0;
  }

  double ring_rate_v_per_block = 0.01;
  double decay_per_block = 1e-6;
  double theta_rate_rad_per_block = 0.0;
  double pattern_rate_rad_per_block = 1e-3;
  bool locked = true;

  void set_amplitude(double a) { a_a_ = a; }
  double amplitude() const { return a_a_; }
  double theta() const { return theta_; }
  const fw::ChainCommands& last_commands() const { return last_cmd_; }
  uint32_t calls() const { return calls_; }

 private:
  double a_a_ = 0.0;
  double theta_ = 0.1;
  fw::ChainCommands last_cmd_{};
  uint32_t calls_ = 0;
};

// Records what the firmware asks of the identifier. Back door: health and drift.
class FakeResonatorIdentifier final : public fw::ResonatorIdentifier {
 public:
  void begin_window(double t_s) override {
    ++begun;
    last_begin_s = t_s;
    open = true;
  }
  void add_sample(const fw::ChainRecord&) override { samples += open ? 1 : 0; }
  void end_window() override {
    ++ended;
    open = false;
  }
  void abort_window() override {
    ++aborted;
    open = false;
  }
  void solve() override { ++solves; }
  fw::EstimatorHealth health() const override { return health_; }
  fw::Identification identification() const override { return {}; }
  double drift_rad_s(double, double, double) const override { return drift; }
  double control_drift_rad_s(const fw::ChainRecord&) override { return control_drift; }
  void set_temperature_c(double t_c, bool valid) override {
    temp_c = t_c;
    temp_valid = valid;
    ++temperatures;
  }

  fw::EstimatorHealth health_{};
  double drift = 0.0;
  double control_drift = 0.0;  // D_Phi, rad/s
  uint32_t begun = 0, ended = 0, aborted = 0, samples = 0, solves = 0, temperatures = 0;
  double last_begin_s = 0.0;
  double temp_c = 0.0;
  bool temp_valid = false;
  bool open = false;
};

}  // namespace hrg::fakes
