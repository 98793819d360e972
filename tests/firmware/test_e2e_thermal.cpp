// SPDX-License-Identifier: MIT
// The calibration's thermal damping on the main job (default scenario, 365 s,
// damping +0.4 %/degC, the resonator's temperature +-1 degC at 5 mHz): with
// the coefficient in force the firmware refers its damping regressors and
// the drift to the temperature its sensor measures, and the common damping's
// thermal change is no longer taken for anisotropy; with the coefficient's
// sign wrong, no output worse than raw is reported valid.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sim_run/run.hpp"
#include "sim_run/scenario_run.hpp"

#include "support/cpputest.hpp"

TEST_GROUP(ThermalLoop){// The simulated target is a process-wide singleton whose buffers outlive
                        // the test: its allocations are not leaks of this test.
                        void setup()
                            override{MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads();
}
void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }
}
;

namespace {

using hrg::sim_run::RunConfig;
using hrg::sim_run::RunResult;

constexpr double kBetaPerC = 0.004;

RunConfig thermal_damping_gyro() {
  const char* src = std::getenv("HRG_SOURCE_DIR");
  const std::string dir = src ? src : ".";
  RunConfig j = hrg::sim_run::run_from_scenario(dir + "/sim_target/scenarios/default.toml", {});
  j.sim.effects.thermal_damping.enabled = true;
  j.sim.effects.thermal_damping.rel_per_c = kBetaPerC;
  j.sim.temp_c = hrg::sim::Profile::sine(1.0, 0.005, 0.0);
  j.sim.temp_c.add_offset(j.sim.resonator.temp_ref_c);
  return j;
}

RunResult with_coefficient(double beta_per_c) {
  RunConfig j = thermal_damping_gyro();
  j.firmware.calibration.thermal_damping_per_c = beta_per_c;
  j.firmware.calibration.temperature_ref_c = j.sim.resonator.temp_ref_c;
  return hrg::sim_run::run_simulation(j, {});
}

}  // namespace

TEST(ThermalLoop, TheThermalDampingCoefficientRemovesItsBiasAndAWrongSignDoesNoHarm) {
  const RunResult seed = with_coefficient(0.0);
  const RunResult right = with_coefficient(kBetaPerC);
  const RunResult wrong = with_coefficient(-kBetaPerC);
  CHECK(seed.fit_comp.ok && right.fit_comp.ok && wrong.fit_comp.ok);
  const double raw = seed.fit_raw.amplitude();
  const double seed_comp = seed.fit_comp.amplitude();
  const double right_comp = right.fit_comp.amplitude();
  const double wrong_comp = wrong.fit_comp.amplitude();
  std::printf(
      "thermal damping row: raw %.3g, seed model %.3g, right coefficient %.3g (valid %d), "
      "wrong sign %.3g (valid %d, calibration verdict %s) deg/h\n",
      raw, seed_comp, right_comp, right.compensation_valid ? 1 : 0, wrong_comp,
      wrong.compensation_valid ? 1 : 0, hrg::fw::app::to_string(wrong.calibration.verdict));
  // The seed's model alone takes the thermal change of nu (nu beta dT, 1.3e-5
  // 1/s, ~4 deg/h of bias at 4theta, seen by windows at other temperatures)
  // partly for anisotropy; the right coefficient removes at least two thirds
  // of what it leaves (measured: 1.91 -> 0.52 deg/h, clean 0.55).
  CHECK(right.compensation_valid);
  CHECK(right_comp < seed_comp / 3.0);
  // Do no harm: the wrong sign doubles the unexplained change; whatever the
  // model check makes of it, a compensation reported valid is not worse than
  // raw.
  if (wrong.compensation_valid) CHECK(wrong_comp <= raw);
  CHECK(raw > 20.0 * right_comp);
}
