// SPDX-License-Identifier: MIT
#pragma once

#include <cstdlib>
#include <string>

#include "sim_run/scenario_run.hpp"

namespace hrg::test {

// The default scenario (sim_target/scenarios/default.toml) as `hrg sim
// --scenario` runs it, read from the source tree CTest names in
// HRG_SOURCE_DIR (else the working directory).
inline sim_run::RunConfig default_scenario_run(const sim_run::ScheduleOptions& o = {}) {
  const char* src = std::getenv("HRG_SOURCE_DIR");
  const std::string dir = src ? src : ".";
  return sim_run::run_from_scenario(dir + "/sim_target/scenarios/default.toml", o);
}

}  // namespace hrg::test
