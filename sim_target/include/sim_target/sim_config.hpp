// SPDX-License-Identifier: MIT
#pragma once

// Everything that configures the simulated target: resonator, electrodes,
// effects, converters, noise, input profiles and the seed. Built in code by
// tests, or from a TOML scenario by hrg_sim_scenario (host tools only).

#include <array>
#include <cstdint>

#include "sim_target/params.hpp"
#include "sim_target/profile.hpp"

namespace hrg::sim {

// Pickoff ADC (two channels: x = C, y = D).
struct AdcConfig {
  uint32_t sample_rate_hz = 100'000;
  uint32_t block_frames = 100;
  uint32_t bits = 24;                   // left-justified into Q1.31
  double full_scale_v = 2.5;            // volts for Q1.31 = 1.0
  std::array<double, 2> noise_v_rms{};  // white noise per sample, per channel
  std::array<double, 2> offset_v{};     // added before quantisation
};

// Drive DAC (three channels: pump, forcer x, forcer y); same rate and block as the ADC.
struct DacConfig {
  uint32_t bits = 16;
  double full_scale_v = 10.0;    // volts at the electrode for Q1.31 = 1.0
  uint32_t latency_samples = 0;  // extra pipeline delay after the one-block double buffer
};

// In-memory CAN controller model.
struct CanConfig {
  uint32_t tx_queue_frames = 32;
  uint32_t tx_frames_per_ms = 8;  // frames leaving the queue per millisecond (about 1 Mbit/s)
};

// The board's temperature sensor (hal::TemperatureSensor): what the firmware
// reads of the resonator's temperature, quantised to the millidegree that the
// Linux interfaces (IIO in_temp*_input, hwmon temp*_input) carry. Neither the
// catalogue nor the resonator model has a sensor noise or a thermal lag
// between the resonator and the sensor, so both are off by default; set, the
// reading lags the resonator's temperature (first order) and gains white
// noise per conversion. A coarser part (2^-7 degC, lsb_c 0.0078125) leaves a
// quantisation error that the audit's frequency model integrates into the
// phase: on a +-1 degC, 5 ppm/degC recording it then also reports a 0.026 deg
// pickoff phase mismatch (6 sigma) that is not there.
struct TemperatureSensorConfig {
  bool present = true;
  double lsb_c = 0.001;      // resolution, degC; 0: not quantised
  double lag_s = 0.0;        // time constant behind the resonator's temperature
  double noise_c_rms = 0.0;  // per conversion
};

// Resonator state at t = 0.
struct InitialWave {
  double amplitude_v = 0.0;  // a_A
  double theta_rad = 0.0;    // pattern angle (physical)
  double quad_v = 0.0;       // a_B
};

struct SimConfig {
  ResonatorParams resonator;
  ElectrodeParams electrodes;
  Effects effects;
  AdcConfig adc;
  DacConfig dac;
  CanConfig can;
  TemperatureSensorConfig temperature_sensor;
  Profile rate_rad_s = Profile::constant(0.0);
  Profile temp_c = Profile::constant(25.0);
  InitialWave initial;
  uint64_t seed = 1;  // fixes every noise source: same seed, same bits
};

}  // namespace hrg::sim
