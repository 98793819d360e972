// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>

#include "dsp/chain.hpp"
#include "firmware/estimator_health.hpp"
#include "hal/converters.hpp"

namespace hrg::fw {

// What the firmware asks of the signal chain for one block.
struct ChainCommands {
  bool pump_on = false;          // mode policy: ring electrode may be driven
  bool forcers_on = false;       // mode policy: x/y forcers may be driven
  bool ring_up = false;          // excite from rest (direct drive at the NCO frequency)
  bool pattern_control = false;  // drive theta_A towards pattern_target_rad
  double pattern_target_rad = 0.0;
  double amplitude_set_v = 1.0;  // AGC set point for a_A
};

// One block of the signal chain as the firmware records it: the chain's
// outputs (quadratures, wave variables, unwrapped angle, PLL, drives and the
// control-loop drift inputs, SI units; dsp/chain.hpp) stamped with the time of
// the block's end on the board's clock. The estimator's samples, the output
// and the telemetry are all read from this one record.
struct ChainRecord : dsp::ChainOutputs {
  double t_s = 0.0;        // time of the block end
  uint32_t nco_phase = 0;  // NCO phase at that time (first sample after the block), 2^-32 cycles
};

// The DSP chain as the firmware sees it: once per ADC block, ADC block in, DAC
// block out. Implemented by an adapter over dsp::Chain (or a fake in tests).
class SignalChain {
 public:
  virtual ~SignalChain() = default;
  // `adc`: interleaved [x, y] frames; `dac`: interleaved [pump, fx, fy] frames
  // to fill. Task context, once per base frame; must not allocate.
  virtual void process(std::span<const hal::q31_t> adc, std::span<hal::q31_t> dac,
                       const ChainCommands& cmd, ChainRecord& out) = 0;
  // nullptr when the chain's configuration is usable, else what is wrong
  // (the firmware then keeps the drives off).
  virtual const char* config_error() const { return nullptr; }
};

// Identified drift model and its uncertainty, p = (nu, dnu_C, dnu_S, dw_C, dw_S).
struct Identification {
  bool valid = false;
  double p[5] = {0, 0, 0, 0, 0};
  double sigma[5] = {0, 0, 0, 0, 0};
};

// The estimator as the firmware sees it (seed sections 3-5).
class ResonatorIdentifier {
 public:
  virtual ~ResonatorIdentifier() = default;
  // Free-decay window bracket; samples in between feed the least squares.
  virtual void begin_window(double t_s) = 0;
  virtual void add_sample(const ChainRecord& s) = 0;
  virtual void end_window() = 0;
  // A check window: tested against the model in force, not folded into it.
  virtual void end_check_window() { end_window(); }
  virtual void abort_window() = 0;
  // Slow task: refresh the solution from the accumulated normal equations.
  virtual void solve() = 0;
  virtual EstimatorHealth health() const = 0;
  virtual Identification identification() const = 0;
  // Modelled drift D_nu + D_w (rad/s, Omega K units) at the current pattern
  // angle and quadrature ratio (seed eq. 22), its damping referred to the
  // wave's energy e_v2 = a_A^2 + a_B^2 (V^2) and the last measured
  // temperature; 0 while nothing is identified.
  virtual double drift_rad_s(double theta_a_rad, double ab_over_aa, double e_v2) const = 0;
  // The resonator's temperature from the board's sensor (degC), at the
  // temperature task's rate; `valid` false while the board has none (the
  // resonator model is then taken at its reference temperature).
  virtual void set_temperature_c(double temp_c, bool valid) {
    (void)temp_c;
    (void)valid;
  }
  // Control-loop drift D_Phi (seed sections 6-7, eq. 23): fed with the
  // excitation on, added to the output only with the excitation on.
  virtual void add_control_sample(const ChainRecord& s) { (void)s; }
  // D_Phi at the record's pattern angle; called once per output frame with
  // the excitation on (a known gap's part follows the wave's amplitude from
  // one call to the next).
  virtual double control_drift_rad_s(const ChainRecord& s) {
    (void)s;
    return 0.0;
  }
};

}  // namespace hrg::fw
