// SPDX-License-Identifier: MIT
#pragma once

#include <string>

#include "sim_run/run.hpp"

namespace hrg::sim_run {

// The run options of `hrg sim` that shape the schedule.
struct ScheduleOptions {
  double duration_s = 0.0;  // 0: the schedule's own length
  int bias_angles = 0;      // parked angles of the bias test; 0: not given (16)
  bool static_base = false;
};

// The job `hrg sim` runs: the default job, or the scenario file's resonator,
// converters, rate and effects under the schedule the options ask for.
//  - A scenario with a constant rate gets the default rate-table schedule
//    (sweep, then the parked-angle bias test) on top of that rate, or with
//    `static_base` no table at all: the firmware turns the pattern itself.
//  - A scenario with its own rate profile runs as given for `duration_s`
//    (default 120 s), without parks.
// Combinations with no meaning are refused, never dropped: a static base with
// a rate profile or with parked angles, parked angles with a rate profile.
// Throws std::invalid_argument naming the options, sim::ScenarioError naming
// the key, or std::runtime_error.
RunConfig make_run(const std::string& scenario_path, const ScheduleOptions& o);

// Copies job.sim's resonator and electrodes into the firmware's configuration
// (K, chain centre and PLL range, Q, pump and forcer gains) and checks that
// the chain can serve it. Throws std::invalid_argument naming `what`.
void adopt_resonator(RunConfig& job, const std::string& what);

// A job from a TOML scenario (sim_target/scenarios/*.toml), as make_run.
RunConfig run_from_scenario(const std::string& path, const ScheduleOptions& o);

}  // namespace hrg::sim_run
