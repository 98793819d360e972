// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>

#include "firmware/shutdown_scheduler.hpp"
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

// Slow (one per block) outputs of the signal chain, SI units.
struct ChainOutputs {
  double t_s = 0.0;                                       // time of the block end
  double cx_v = 0.0, sx_v = 0.0, cy_v = 0.0, sy_v = 0.0;  // demodulated quadratures
  double e_v2 = 0.0;                                      // E = a_A^2 + a_B^2
  double a_a_v = 0.0;                                     // working wave amplitude
  double a_b_v = 0.0;                                     // quadrature wave amplitude (signed)
  double theta_a_rad = 0.0;                               // pattern angle, (-pi/4, pi/4]
  double f_ref_hz = 0.0;                                  // NCO (reference) frequency
  double pump_v = 0.0;                                    // pump amplitude being output
  double quad_effort = 0.0;                               // quadrature forcer command, -1..1
  // Control-loop drift inputs (seed sections 6-7): the pump phase error
  // eps = pi/2 - 2 (phi_V - phi_A) and the quadrature forcers' commanded
  // action, the part on a_B' (sin) and the part on the angle (cos), V/s.
  double pump_phase_error_rad = 0.0;
  double quad_sin_v_s = 0.0;
  double quad_cos_v_s = 0.0;
  bool locked = false;  // PLL lock detector
};

// The DSP chain as the firmware sees it: once per ADC block, ADC block in, DAC
// block out. Implemented by an adapter over dsp::Chain (or a fake in tests).
class SignalChain {
 public:
  virtual ~SignalChain() = default;
  // `adc`: interleaved [x, y] frames; `dac`: interleaved [pump, fx, fy] frames
  // to fill. Task context, once per base frame; must not allocate.
  virtual void process(std::span<const hal::sample_q31> adc, std::span<hal::sample_q31> dac,
                       const ChainCommands& cmd, ChainOutputs& out) = 0;
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
class Identifier {
 public:
  virtual ~Identifier() = default;
  // Free-decay window bracket; samples in between feed the least squares.
  virtual void begin_window(double t_s) = 0;
  virtual void add_sample(const ChainOutputs& s) = 0;
  virtual void end_window() = 0;
  virtual void abort_window() = 0;
  // Slow task: refresh the solution from the accumulated normal equations.
  virtual void solve() = 0;
  virtual EstimatorHealth health() const = 0;
  virtual Identification identification() const = 0;
  // Modelled drift D_nu + D_w (rad/s, Omega K units) at the current pattern
  // angle and quadrature ratio (seed eq. 22); 0 while nothing is identified.
  virtual double drift_rad_s(double theta_a_rad, double ab_over_aa) const = 0;
  // Control-loop drift D_Phi (seed sections 6-7, eq. 23): fed with the
  // excitation on, added to the output only with the excitation on.
  virtual void add_control_sample(const ChainOutputs& s) { (void)s; }
  virtual double control_drift_rad_s(double theta_a_rad) const {
    (void)theta_a_rad;
    return 0.0;
  }
};

}  // namespace hrg::fw
