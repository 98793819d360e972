// SPDX-License-Identifier: MIT
#include "sim_tools/scenario_job.hpp"

#include <stdexcept>

#include "dsp/chain.hpp"
#include "sim_target/scenario.hpp"

namespace hrg::simtools {

JobConfig job_from_scenario(const std::string& path, double duration_s, int bias_angles) {
  const sim::SimConfig sc = sim::load_scenario(path);
  JobConfig job = default_job(duration_s, bias_angles);
  const sim::Profile schedule = job.sim.rate_rad_s;
  const double default_earth = job.earth_rate_rad_s;
  job.sim = sc;
  job.description = "scenario " + path;
  if (sc.rate_rad_s.is_constant()) {
    // The rate table's schedule on top of the scenario's constant rate.
    sim::Profile p = schedule;
    p.add_offset(sc.rate_rad_s.value(0.0) - default_earth);
    job.sim.rate_rad_s = p;
    job.earth_rate_rad_s = sc.rate_rad_s.value(0.0);
    job.description += " with the default rate-table schedule";
  } else {
    job.parks.clear();
    job.duration_s = duration_s > 0 ? duration_s : 120.0;
    job.sweep_end_s = job.duration_s;
    job.earth_rate_rad_s = 0.0;
  }
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
    throw std::invalid_argument("scenario " + path + ": signal chain configuration: " + err);
  return job;
}

}  // namespace hrg::simtools
