// SPDX-License-Identifier: MIT
#pragma once

// TOML scenario -> SimConfig (library hrg_sim_scenario, host tools only: the
// Linux board builds have no toml++). Every value carries its unit in the key
// name (f_hz, split_hz, th_w_deg, noise_x_v_rms, ...); degrees and deg/s are
// converted to SI here. Unknown keys and out-of-range values are rejected with
// the full dotted key name and the allowed range. See
// sim_target/scenarios/default.toml for every key.

#include <stdexcept>
#include <string>
#include <string_view>

#include "sim_target/sim_config.hpp"

namespace hrg::sim {

class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses a scenario text. `source` names it in error messages; relative table
// file paths are resolved against `base_dir`.
SimConfig parse_scenario(std::string_view toml_text, const std::string& source = "<scenario>",
                         const std::string& base_dir = ".");

// Reads and parses a scenario file.
SimConfig load_scenario(const std::string& path);

}  // namespace hrg::sim
