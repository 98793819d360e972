// SPDX-License-Identifier: MIT
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "campaign.hpp"
#include "sim_run/run.hpp"
#include "sim_run/report.hpp"
#include "sim_run/table_schedule.hpp"

namespace hrg::audit::bench {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kRampS = 1.0;  // the table's acceleration ramps

// Cruise time of the main job's sweep at the scenario's table rate.
double cruise_s(const Scenario& s) {
  return sim_run::sweep_case_rad(s.resonator.angular_gain) / std::abs(s.sweep_rate_dps * kDeg) -
         kRampS;
}

// The table: still while the firmware rings up, then the main job's sweep
// (the pattern twice through the 4 theta circle) in the scenario's
// direction, then still again.
sim::Profile sweep_profile(const Scenario& s, double earth_rad_s) {
  const double rate = s.sweep_rate_dps * kDeg;
  sim_run::TableSchedule sch;
  sch.hold(sim_run::kRingUpS);
  sch.turn(std::copysign(sim_run::sweep_case_rad(s.resonator.angular_gain), rate), rate, kRampS);
  return sch.profile(earth_rad_s);
}

sim_run::RunConfig firmware_job(const Scenario& s) {
  sim_run::RunConfig j = sim_run::default_run(s.duration_s, 16);
  j.description =
      "audit benchmark: the firmware's telemetry (interval shutdown while the table turns)";
  j.parks.clear();
  j.duration_s = s.duration_s;
  sim::SimConfig& c = j.sim;
  c.resonator = s.resonator;
  c.electrodes.pump_gain_per_s2_v2 = s.electrodes.pump_gain_per_s2_v2;
  c.electrodes.eps_p = s.electrodes.eps_p;
  c.electrodes.eps_q = s.electrodes.eps_q;
  c.effects = s.effects;
  c.seed = s.seed;
  // White ADC noise that gives the scenario's noise per demodulated signal
  // (the chain's own conversion, see sim_run::RunResult::noise_sigma_v).
  const double adc_noise_v = s.noise_v * std::sqrt(0.5 * static_cast<double>(c.adc.block_frames));
  c.adc.noise_v_rms = {adc_noise_v, adc_noise_v};
  c.rate_rad_s = sweep_profile(s, j.earth_rate_rad_s);
  c.temp_c = temperature_profile(s, s.temp_phase_rad);
  j.sweep_end_s = j.duration_s;
  fw::GyroConfig& g = j.firmware.gyro;
  g.amplitude_set_v = s.amplitude_v;
  g.windows.length_frames = static_cast<uint32_t>(std::lround(s.window_s * 1000.0));
  g.windows.period_frames = 2 * g.windows.length_frames;
  sim_run::derive_firmware_config(j);
  return j;
}

}  // namespace

double firmware_duration_s(const Scenario& s) {
  return sim_run::kRingUpS + cruise_s(s) + 2.0 * kRampS + 10.0;
}

recording::Recording simulate_firmware(const Scenario& s) {
  const sim_run::RunConfig job = firmware_job(s);
  const sim_run::RunResult r = sim_run::run_simulation(job, {});
  if (!r.reached_operate || r.windows == 0) {
    throw std::runtime_error("firmware campaign (seed " + std::to_string(s.seed) +
                             ") never reached operate with free-decay windows");
  }
  return sim_run::telemetry_recording(job, r);
}

}  // namespace hrg::audit::bench
