// SPDX-License-Identifier: MIT
#include "sim_run/scenario_run.hpp"

#include <stdexcept>

#include "dsp/chain.hpp"
#include "sim_target/scenario.hpp"

namespace hrg::sim_run {

namespace {

constexpr int kDefaultBiasAngles = 16;

// Options that contradict each other or the scenario are refused here, before
// anything runs ("" for no scenario).
void refuse_conflicts(const std::string& path, bool own_profile, const ScheduleOptions& o) {
  if (o.static_base && o.bias_angles > 0)
    throw std::invalid_argument(
        "--bias-angles parks a rate table at angles; a --static-base run has no table (choose "
        "one)");
  if (!own_profile) return;
  if (o.static_base)
    throw std::invalid_argument("scenario " + path +
                                " has its own rate profile ([rate] kind is not \"constant\"); "
                                "--static-base would replace it (drop one of them)");
  if (o.bias_angles > 0)
    throw std::invalid_argument("scenario " + path +
                                " has its own rate profile; its run has no parked-angle bias "
                                "test for --bias-angles (use a constant [rate] to get one)");
}

}  // namespace

void adopt_resonator(RunConfig& job, const std::string& what) {
  const sim::SimConfig& sc = job.sim;
  job.firmware.gyro.angular_gain = sc.resonator.angular_gain;
  derive_firmware_config(job);
  job.firmware.chain.f_center_hz = sc.resonator.f_hz;
  job.firmware.chain.f_min_hz = sc.resonator.f_hz - 10.0;
  job.firmware.chain.f_max_hz = sc.resonator.f_hz + 10.0;
  job.firmware.chain.q_factor = sc.resonator.q;
  job.firmware.chain.pump_gain_per_s2_v2 = sc.electrodes.pump_gain_per_s2_v2;
  job.firmware.chain.forcer_gain_per_s2 = sc.electrodes.forcer_gain_per_s2;
  // The PLL range above (+-10 Hz about the resonance) and the converters
  // must still make a usable chain (e.g. the NCO's periodicity rule).
  if (const char* err = dsp::check_chain_config(job.firmware.chain))
    throw std::invalid_argument(what + ": signal chain configuration: " + err);
}

RunConfig make_run(const std::string& scenario_path, const ScheduleOptions& o) {
  if (!scenario_path.empty()) return run_from_scenario(scenario_path, o);
  refuse_conflicts("", false, o);
  if (o.static_base) return static_base_run(o.duration_s);
  return default_run(o.duration_s, o.bias_angles > 0 ? o.bias_angles : kDefaultBiasAngles);
}

RunConfig run_from_scenario(const std::string& path, const ScheduleOptions& o) {
  const sim::SimConfig sc = sim::load_scenario(path);
  const bool own_profile = !sc.rate_rad_s.is_constant();
  refuse_conflicts(path, own_profile, o);
  const int bias_angles = o.bias_angles > 0 ? o.bias_angles : kDefaultBiasAngles;
  RunConfig job =
      o.static_base ? static_base_run(o.duration_s) : default_run(o.duration_s, bias_angles);
  const sim::Profile schedule = job.sim.rate_rad_s;
  const double default_earth = job.earth_rate_rad_s;
  job.sim = sc;
  job.description = "scenario " + path;
  if (own_profile) {
    job.parks.clear();
    job.duration_s = o.duration_s > 0 ? o.duration_s : 120.0;
    job.sweep_end_s = job.duration_s;
    job.earth_rate_rad_s = 0.0;
  } else if (o.static_base) {
    // The scenario's constant rate alone; the firmware turns the pattern.
    job.earth_rate_rad_s = sc.rate_rad_s.value(0.0);
    job.description += " on a static base (the firmware turns the pattern)";
  } else {
    // The rate table's schedule on top of the scenario's constant rate.
    sim::Profile p = schedule;
    p.add_offset(sc.rate_rad_s.value(0.0) - default_earth);
    job.sim.rate_rad_s = p;
    job.earth_rate_rad_s = sc.rate_rad_s.value(0.0);
    job.description += " with the default rate-table schedule";
  }
  adopt_resonator(job, "scenario " + path);
  return job;
}

}  // namespace hrg::sim_run
