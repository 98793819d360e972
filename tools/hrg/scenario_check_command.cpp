// SPDX-License-Identifier: MIT
// `hrg scenario-check FILE...`: validates simulator scenario files (TOML) and
// prints what each one configures, or the first error with the key's name.
#include <cmath>
#include <cstdio>
#include <span>
#include <string_view>

#include "sim_target/scenario.hpp"

namespace hrg::cli {

int scenario_check_main(std::span<char* const> args) {
  if (args.empty() || std::string_view(args[0]) == "--help" || std::string_view(args[0]) == "-h") {
    std::fprintf(args.empty() ? stderr : stdout,
                 "usage: hrg scenario-check FILE...\n\n"
                 "Checks simulator scenario files (TOML, see sim_target/scenarios/default.toml):\n"
                 "unknown keys and out-of-range values are reported with the key's dotted\n"
                 "name and the allowed range. Exit status 1 if any file is invalid.\n");
    return args.empty() ? 2 : 0;
  }
  int status = 0;
  for (char* const path : args) {
    try {
      const sim::SimConfig c = sim::load_scenario(path);
      int effects_on = 0;
      const auto& fx = c.effects;
      for (bool on :
           {fx.pickoff_gain_mismatch.enabled, fx.pickoff_phase_mismatch.enabled,
            fx.pickoff_misalignment.enabled, fx.duffing_stiffness.enabled,
            fx.nonlinear_damping.enabled, fx.thermal_frequency.enabled, fx.thermal_damping.enabled,
            fx.electrostatic_spring.enabled, fx.drive_feedthrough.enabled}) {
        effects_on += on ? 1 : 0;
      }
      const double v_th =
          c.electrodes.threshold_v(c.resonator.omega_rad_s(), c.resonator.nu_per_s());
      std::printf(
          "%s: ok: f %.6g Hz, Q %.4g, dmu %.4g, split %.4g Hz, K %.4g; pump threshold %.3f V; "
          "ADC %u Hz x %u bits, block %u; rate at t=0 %.6g deg/h; %d effect(s) on; seed %llu\n",
          path, c.resonator.f_hz, c.resonator.q, c.resonator.dmu, c.resonator.split_hz,
          c.resonator.angular_gain, v_th, c.adc.sample_rate_hz, c.adc.bits, c.adc.block_frames,
          c.rate_rad_s.value(0.0) / sim::kDegToRad * 3600.0, effects_on,
          static_cast<unsigned long long>(c.seed));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s\n", e.what());
      status = 1;
    }
  }
  return status;
}

}  // namespace hrg::cli
