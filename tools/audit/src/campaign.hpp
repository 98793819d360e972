// SPDX-License-Identifier: MIT
#pragma once

// Synthetic campaigns for the audit benchmark: sim_target's averaged model
// driven by a simple envelope controller, recorded as hrg-recording v1 with
// white noise on the demodulated signals.
//  - ring-down: a few seconds of excitation (amplitude to its set point, the
//    pump nulls the quadrature, forcers move the pattern to a new angle), then
//    a free decay of 10-30 s, some under a turning rate table, one long decay;
//  - telemetry: the firmware's interval shutdown, excitation for 4-10 s with
//    the pattern free under a stepped rate, short free windows of 0.4-2 s.
// And from the firmware itself:
//  - firmware: `hrg sim`'s job (the firmware's dsp chain, loops and window
//    scheduler against sim_target's full-rate resonator in lockstep): ring-up
//    from rest, the table turning the pattern twice through the 4 theta
//    circle with 0.3-1 s windows, recorded as the job's telemetry.

#include <cstdint>
#include <random>
#include <string>

#include "audit/bench.hpp"
#include "recording/recording.hpp"
#include "sim_target/params.hpp"
#include "sim_target/profile.hpp"

namespace hrg::audit::bench {

// Structure outside the catalogue, for the audit's description.
enum class OutsideEffect {
  none,
  gain_ratio_drift,    // y pickoff gain (1 + v (t - t_mid)/1 h)
  phase_drift,         // y pickoff phase lag v (t - t_mid)/1 h (rad)
  offset_x,            // constant offset of magnitude v (V) on cx_v/sx_v
  gain_ratio_vs_temp,  // y pickoff gain (1 + v (T - T_mean)) (1/degC)
};
inline constexpr int kOutsideEffectCount = 4;
const char* outside_name(OutsideEffect e);
bool outside_by_name(const std::string& name, OutsideEffect& e);

struct Scenario {
  Design design = Design::ringdown;
  sim::ResonatorParams resonator;
  sim::ElectrodeParams electrodes;
  sim::Effects effects;
  double f_ref_hz = 5000.0;
  double amplitude_v = 1.0;  // set point of the excitation
  double noise_v = 1e-5;     // white noise per demodulated signal
  double duration_s = 600.0;
  double sample_rate_hz = 200.0;
  double temp_mean_c = 25.0, temp_swing_c = 1.0;  // slow temperature swing
  double temp_phase_rad = 0.0;
  bool temp_cycles = false;  // see temperature_profile()
  // Beyond sim_target, applied to the recorded signals (outside_effects.cpp):
  // 1/f-like noise on each demodulated signal, its spectral density equal to
  // the white noise's at this corner (0: white noise only); one effect the
  // catalogue does not hold; a demodulation reference that follows the
  // resonance like a PLL (the f_ref_hz column changes per row).
  double flicker_corner_hz = 0.0;
  OutsideEffect outside = OutsideEffect::none;
  double outside_value = 0.0;  // see OutsideEffect
  bool pll_reference = false;
  // Firmware campaigns only.
  double window_s = 1.0;         // free-decay window length
  double sweep_rate_dps = 10.0;  // case rate of the table's turn
  uint64_t seed = 1;
};

// The campaign's temperature about s.temp_mean_c with a swing of
// s.temp_swing_c and phase `phase_rad`: a sine of 1.3 run lengths (it
// follows time over the run), or with s.temp_cycles two cycles over the run
// with their straight line in time taken out, so that a thermal effect and
// a drift in time predict different things (uncorrelated with time).
sim::Profile temperature_profile(const Scenario& s, double phase_rad);

// A random resonator, noise and campaign of the given design (effects off).
Scenario random_scenario(Design design, double duration_s, uint64_t seed);

// Turns on catalogue effect `id` with catalogue value `value` (feedthrough:
// the larger pickoff; the other pickoff and the phases are drawn from `seed`).
// False for an unknown id.
bool conceal_by_id(Scenario& s, const std::string& id, double value, uint64_t seed);

// Simulates the campaign and returns the recording (deterministic in seed).
recording::Recording simulate(const Scenario& s);

// Applies the scenario's coloured noise, outside effect and PLL reference to
// a simulated recording (deterministic in the scenario's seed).
void apply_outside_effects(const Scenario& s, recording::Recording& rec);

// The firmware campaign (simulate() of Design::firmware) and its length: the
// ring-up, the table's turn and 10 s after it.
recording::Recording simulate_firmware(const Scenario& s);
double firmware_duration_s(const Scenario& s);

}  // namespace hrg::audit::bench
