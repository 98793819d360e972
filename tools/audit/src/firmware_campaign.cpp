// SPDX-License-Identifier: MIT
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "campaign.hpp"
#include "sim_tools/job.hpp"
#include "sim_tools/report.hpp"

namespace hrg::audit::bench {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kRingUpS = 45.0;  // ring-up from rest and lock (the main job's first hold)
constexpr double kRampS = 1.0;     // the table's acceleration ramps

// Case angle of the table's turn: the pattern (at -K/2 of it) goes twice
// through the 4 theta circle, 180 deg of theta.
double turn_case_rad(const Scenario& s) {
  return 2.0 * (kPi / 2.0) * 2.0 / s.resonator.angular_gain;
}

// Cruise time of that turn at the scenario's table rate.
double cruise_s(const Scenario& s) {
  return turn_case_rad(s) / std::abs(s.sweep_rate_dps * kDeg) - kRampS;
}

// The table: still while the firmware rings up, then one turn of the case
// that takes the pattern twice through the 4 theta circle (the main job's
// sweep), then still again.
sim::Profile sweep_profile(const Scenario& s, double earth_rad_s) {
  const double rate = s.sweep_rate_dps * kDeg;
  const double t0 = kRingUpS;
  const double cruise = cruise_s(s);
  return sim::Profile::ramps({{0.0, 0.0},
                              {t0, 0.0},
                              {t0 + kRampS, rate},
                              {t0 + kRampS + cruise, rate},
                              {t0 + 2.0 * kRampS + cruise, 0.0}})
      .add_offset(earth_rad_s);
}

simtools::JobConfig firmware_job(const Scenario& s) {
  simtools::JobConfig j = simtools::default_job(s.duration_s, 16);
  j.description =
      "audit benchmark: the firmware's telemetry (interval shutdown while the table turns)";
  j.parks.clear();
  j.duration_s = s.duration_s;
  sim::SimConfig& c = j.sim;
  c.resonator = s.resonator;
  c.electrodes.pump_gain_per_s2_v2 = s.electrodes.pump_gain_per_s2_v2;
  c.effects = s.effects;
  c.seed = s.seed;
  // White ADC noise that gives the scenario's noise per demodulated signal
  // (the chain's own conversion, see simtools::JobResult::noise_sigma_v).
  const double adc_noise_v = s.noise_v * std::sqrt(0.5 * static_cast<double>(c.adc.block_frames));
  c.adc.noise_v_rms = {adc_noise_v, adc_noise_v};
  c.rate_rad_s = sweep_profile(s, j.earth_rate_rad_s);
  c.temp_c = sim::Profile::sine(s.temp_swing_c, 1.0 / (1.3 * s.duration_s), s.temp_phase_rad)
                 .add_offset(s.temp_mean_c);
  j.sweep_end_s = j.duration_s;
  fw::GyroConfig& g = j.firmware.gyro;
  g.amplitude_set_v = s.amplitude_v;
  g.windows.length_frames = static_cast<uint32_t>(std::lround(s.window_s * 1000.0));
  g.windows.period_frames = 2 * g.windows.length_frames;
  simtools::derive_firmware_config(j);
  return j;
}

}  // namespace

double firmware_duration_s(const Scenario& s) {
  return kRingUpS + cruise_s(s) + 2.0 * kRampS + 10.0;
}

recording::Recording simulate_firmware(const Scenario& s) {
  const simtools::JobConfig job = firmware_job(s);
  const simtools::JobResult r = simtools::run_job(job, {});
  if (!r.reached_operate || r.windows == 0) {
    throw std::runtime_error("firmware campaign (seed " + std::to_string(s.seed) +
                             ") never reached operate with free-decay windows");
  }
  return simtools::telemetry_recording(job, r);
}

}  // namespace hrg::audit::bench
