// SPDX-License-Identifier: MIT
#pragma once

#include <string>

#include "sim_tools/job.hpp"

namespace hrg::simtools {

// A job from a TOML scenario (sim_target/scenarios/*.toml). A scenario with a
// constant rate gets the default job's rate-table schedule (sweep, then the
// parked-angle bias test) on top of that rate; a scenario with its own rate
// profile runs as given for `duration_s` (default 120 s) without parks.
// Throws sim::ScenarioError (naming the key) or std::runtime_error.
JobConfig job_from_scenario(const std::string& path, double duration_s, int bias_angles);

}  // namespace hrg::simtools
