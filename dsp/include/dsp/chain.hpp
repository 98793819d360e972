// SPDX-License-Identifier: MIT
#pragma once

// The whole-angle signal chain, called once per ADC block by the firmware:
//
//   ADC block (Q1.31 [x, y] frames)
//     -> NCO + mixing + sinc^5 decimation (fast path, type T)  -> cx, sx, cy, sy
//     -> wave variables, theta_A unwrapping                    (control rate, double)
//     -> PLL on the wave phase, AGC through the pump, quadrature nulling,
//        optional pattern-angle command, ring-up from rest
//     -> drive synthesis: DAC block (Q1.31 [pump, fx, fy] frames)
//
// T is q31_t (bit-exact on the Cortex-M7), float or double. The control-rate
// part is double in all variants. No heap, no exceptions; process() does a
// fixed amount of work per call.
//
// Drive conventions (physics.md sections 2 and 4, seed section 6), with
// psi = NCO phase + the measured wave phase, c2 = cos 2theta_A, s2 = sin 2theta_A:
// - pump V = V0 cos(psi + pi/4): the 2w part of V^2 = V0^2/2 cos(2 psi + pi/2)
//   times the displacement a cos psi leaves k V0^2 a / 4 cos(psi + pi/2) at w,
//   in phase with the velocity: wave A grows at k_pump V0^2 / (8 w);
// - ring-up: forcers along the pattern (c2, s2), V_f = -u_a sin psi, in phase
//   with the velocity: a_A' = g u_a / (2 w);
// - quadrature: forcers along the node (-s2, c2), V_f = u_q cos psi (in phase
//   with the displacement of A, in quadrature with wave B): a_B' = g u_q / (2 w);
// - pattern angle: forcers along the node, V_f = -u_r sin psi:
//   theta_A' = g u_r / (4 w a_A).

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "dsp/demodulator.hpp"
#include "dsp/electronics_correction.hpp"
#include "dsp/fixed.hpp"
#include "dsp/loops.hpp"
#include "dsp/nco.hpp"
#include "dsp/sample.hpp"
#include "dsp/wave_variables.hpp"

namespace hrg::dsp {

inline constexpr std::size_t kChainAdcChannels = 2;  // x (C), y (D)
inline constexpr std::size_t kChainDacChannels = 3;  // pump, forcer x, forcer y

struct ChainConfig {
  double sample_rate_hz = 100000.0;
  uint32_t block_frames = 100;     // ADC/DAC frames per call = decimation ratio
  double adc_full_scale_v = 2.0;   // pickoff volts at Q1.31 full scale
  double dac_full_scale_v = 10.0;  // electrode volts at Q1.31 full scale
  // DAC frame j written after ADC block n acts on the resonator at the time
  // of ADC frame n * L + dac_lead_frames + j: one block of double buffering
  // plus half a frame for the zero-order hold (its effective delay).
  double dac_lead_frames = 100.5;
  // Resonator and electrodes (nominal; loop gains are normalised by them).
  double f_center_hz = 5000.0;
  double f_min_hz = 4990.0;
  double f_max_hz = 5010.0;
  double q_factor = 5.0e6;
  double pump_gain_per_s2_v2 = 87.73;  // F = k_pump V^2 [x, y]
  double forcer_gain_per_s2 = 200.0;   // F = g V_f
  // Set points and limits.
  double amplitude_setpoint_v = 1.0;
  double pump_phase_rad = 0.7853981633974483;  // phi_V - wave phase: pi/4 adds energy to A
  double pump_max_v = 10.0;
  double forcer_max_v = 5.0;
  // Loop dynamics.
  double pll_natural_hz = 12.0;
  double pll_damping = 0.9;
  double agc_natural_rad_s = 8.0;
  double agc_damping = 1.0;
  double quad_natural_rad_s = 30.0;
  double quad_damping = 1.0;
  double pattern_gain_per_s = 5.0;  // angle command loop: theta' = k (target - theta)
  // Ring-up and validity.
  // Below this a_A the phase is not measured (PLL holds, drive phase frozen).
  // Keep it low but above the demodulated noise floor: during ring-up from
  // rest the drive only follows the resonance (self-excitation through the
  // measured wave phase) once the wave is above it; until then it drives at
  // the NCO frequency, whose off-resonance response stays near
  // g u / (2 w dw) = 2.5e-4 V at 10 Hz off.
  double min_amplitude_v = 1e-4;
  double ring_up_enter = 0.1;      // ring-up when a_A < enter * set point
  double ring_up_exit = 0.9;       // pump-only once a_A > exit * set point
  double ring_up_theta_rad = 0.0;  // pattern angle to ring up at from rest
  double lock_enter_rad = 0.01;
  double lock_exit_rad = 0.05;
  uint32_t lock_blocks = 200;
};

// Returns nullptr when the configuration is usable, else a message naming the
// first bad field. A PLL range outside the band the decimator serves
// (decimator_band: 1594..48406 Hz at 100 kHz with 100-frame blocks) is
// refused naming the frequency, the band and the block length or sample rate
// that would serve it; that message is held in one static buffer, valid
// until the next refused configuration.
const char* check_chain_config(const ChainConfig& c);

// Control-loop drift inputs (seed sections 6-7).
// The pump acting during a block was phased from the previous block's wave
// phase; against the wave phase phi_A measured now its error is
// eps = pi/2 - 2 (phi_V - phi_A), wrapped to (-pi, pi]: 0 when the pump
// leads the wave by the ideal quarter turn of 2 phi.
double pump_phase_error_rad(double prev_pump_phase_rad, double wave_phase_rad);
// The quadrature drive u_q (forcer volts along the node, in phase with wave
// A's displacement) changes a_B at g u_q / (2 w), V/s; it has no commanded
// part on the angle.
double quad_force_rate_v_s(double forcer_gain_per_s2, double w_rad_s, double u_q_v);

// Slow outputs, one set per block (control rate), SI units.
struct ChainOutputs {
  Quadratures<double> quad_v;  // cx, sx, cy, sy, volts of pickoff
  WaveVariables<double> wave;  // E, Q, R, S (V^2), a_A, a_B (V), theta wrapped, phase
  double theta_A_rad = 0.0;    // unwrapped pattern angle
  double phase_err_rad = 0.0;  // PLL phase detector output (wave phase mod pi)
  double pll_freq_hz = 0.0;    // NCO frequency for the next block
  double pump_v = 0.0;         // pump amplitude V0 written for the next block
  // Amplitude of the pump envelope that this block's quadratures saw: the
  // decimator's weights over the blocks whose pump acted in its window (what
  // a drive feedthrough in them is proportional to), V.
  double pump_seen_v = 0.0;
  double pump_phase_rad = 0.0;  // phi_V against the NCO
  double quad_effort_v = 0.0;   // u_q, forcer volts along the node
  double quad_effort = 0.0;     // u_q / forcer_max_v, -1..1
  // Control-loop drift inputs: the pump's phase error (0 on the first block
  // and while the pump is off) and the quadrature forcers' commanded action,
  // the part on a_B' (sin) and the part on the angle (cos), V/s. The pattern
  // drive is left out: it turns the pattern on purpose (output held).
  double pump_phase_error_rad = 0.0;
  double quad_force_sin_v_s = 0.0;
  double quad_force_cos_v_s = 0.0;
  double pattern_effort_v = 0.0;  // u_r
  double ring_up_drive_v = 0.0;   // u_a
  bool locked = false;
  bool ring_up = false;
  bool excitation = false;
  uint64_t blocks = 0;
};

template <typename T>
class Chain {
 public:
  using Ops = SampleOps<T>;

  // The configuration must pass check_chain_config (the firmware checks it
  // before constructing); a bad one leaves the chain inert (process() false).
  explicit Chain(const ChainConfig& cfg);

  // Back to rest: filters cleared, loops at their feed-forward values, NCO at
  // the centre frequency, excitation off.
  void reset();

  // Excitation off: every DAC word is exactly zero and the loops hold their
  // state (the PLL keeps tracking a ringing wave). On: ring-up or operation.
  void set_excitation(bool on) { set_drive_enables(on, on); }
  bool excitation() const { return pump_on_ || forcers_on_; }
  // Finer gating (mode policy): the pump and the forcers separately. A drive
  // that is off outputs exactly zero and the loop acting through it holds
  // its state (AGC: pump; quadrature, pattern and ring-up: forcers).
  void set_drive_enables(bool pump_on, bool forcers_on) {
    pump_on_ = pump_on;
    forcers_on_ = forcers_on;
  }

  // Pattern-angle command: with `enabled`, the pattern is steered toward
  // theta_target_rad (unwrapped) at up to max_rate_rad_s; without it no
  // rotating force is applied (whole-angle mode).
  void set_pattern_command(bool enabled, double theta_target_rad, double max_rate_rad_s);
  // AGC set point for a_A, volts of pickoff; must lie in (0, adc_full_scale_v),
  // else it is refused (false) and the previous set point stays.
  bool set_amplitude_setpoint_v(double a_set_v) {
    if (!(a_set_v > 0.0 && a_set_v < cfg_.adc_full_scale_v)) return false;
    agc_.set_setpoint_v(a_set_v);
    return true;
  }

  // One block: adc = block_frames * 2 words, dac = block_frames * 3 words.
  // Returns false (and touches nothing) on a size mismatch or an unusable
  // configuration. Base-frame task context.
  bool process(std::span<const q31_t> adc, std::span<q31_t> dac);

  // Electronics correction (pickoff-map inverse, drive feedthrough) on the
  // demodulated quadratures before the wave variables; false (nothing
  // changed) when a coefficient does not fit the chain's number format.
  bool set_electronics_correction(const PickoffCorrection<double>& pickoff,
                                  const FeedthroughCoefficients<double>& feedthrough_v_per_v) {
    return correction_.configure(pickoff, feedthrough_v_per_v, cfg_.adc_full_scale_v,
                                 cfg_.dac_full_scale_v);
  }
  void clear_electronics_correction() { correction_.clear(); }
  const ElectronicsCorrection<T>& electronics_correction() const { return correction_; }

  const ChainOutputs& outputs() const { return out_; }
  const ChainConfig& config() const { return cfg_; }
  uint32_t nco_phase() const { return phase_; }
  uint32_t nco_step() const { return step_; }

 private:
  void update_loops(const WaveVariables<double>& w, double dt_s);
  void update_drift_inputs(bool had_pump_phase, double prev_pump_phase_rad);
  void synthesize(uint32_t phase_block_start, std::span<q31_t> dac) const;

  ChainConfig cfg_;
  bool usable_ = false;
  Demodulator<T> demod_;
  ElectronicsCorrection<T> correction_;
  PumpEnvelopeFilter pump_seen_;
  Pll pll_;
  LockDetector lock_;
  Agc agc_;
  PiController quad_pi_;
  ThetaUnwrapper<double> unwrap_;
  ChainOutputs out_;
  uint32_t phase_ = 0;
  uint32_t step_ = 0;
  bool pump_on_ = false;
  bool forcers_on_ = false;
  bool ring_up_ = true;
  bool have_pump_phase_ = false;  // out_.pump_phase_rad holds a previous block's
  bool pattern_enabled_ = false;
  double pattern_target_rad_ = 0.0;
  double pattern_max_rate_rad_s_ = 0.0;
  // Drive for the next block (volts) and its geometry.
  double wave_phase_rad_ = 0.0;
  double c2_ = 1.0;
  double s2_ = 0.0;
  double u_a_v_ = 0.0;
  double u_q_v_ = 0.0;
  double u_r_v_ = 0.0;
  double v0_v_ = 0.0;
  // Pump envelope written for the next ADC block (volts, against the NCO).
  double pump_env_re_v_ = 0.0;
  double pump_env_im_v_ = 0.0;
};

extern template class Chain<q31_t>;
extern template class Chain<float>;
extern template class Chain<double>;

}  // namespace hrg::dsp
