// SPDX-License-Identifier: MIT
// The calibration's thermal damping on the main job (default scenario, 365 s,
// damping +0.4 %/degC, the resonator's temperature +-1 degC at 5 mHz): with
// the coefficient in force the firmware refers its damping regressors and
// the drift to the temperature its sensor measures, and the common damping's
// thermal change is no longer taken for anisotropy; with the coefficient's
// sign wrong, the damping model check refutes it and the seed's model is used.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sim_run/run.hpp"
#include "sim_run/scenario_run.hpp"

#include "support/default_scenario.hpp"
#include "support/cpputest.hpp"

TEST_GROUP_WITHOUT_LEAK_CHECK(ThermalLoop);

namespace {

using hrg::sim_run::RunConfig;
using hrg::sim_run::RunResult;

constexpr double kBetaPerC = 0.004;

RunConfig thermal_damping_gyro() {
  RunConfig j = hrg::test::default_scenario_run();
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

TEST(ThermalLoop, TheThermalDampingCoefficientRemovesItsBiasAndAWrongSignIsRefuted) {
  const RunResult seed = with_coefficient(0.0);
  const RunResult right = with_coefficient(kBetaPerC);
  const RunResult wrong = with_coefficient(-kBetaPerC);
  const hrg::fw::app::CalibrationStatus& rc = right.calibration;
  const hrg::fw::app::CalibrationStatus& wc = wrong.calibration;
  const double raw = seed.fit_raw.amplitude();
  const double seed_comp = seed.fit_comp.amplitude();
  const double right_comp = right.fit_comp.amplitude();
  const double wrong_comp = wrong.fit_comp.amplitude();
  std::printf(
      "thermal damping row: raw %.3g, seed model %.3g, right coefficient %.3g (valid %d), "
      "wrong sign %.3g (valid %d) deg/h\n",
      raw, seed_comp, right_comp, right.compensation_valid ? 1 : 0, wrong_comp,
      wrong.compensation_valid ? 1 : 0);
  std::printf(
      "damping model check: right f %.3f +- %.3f (refuted %d); wrong sign f %.3f +- %.3f "
      "(refuted %d at %.1f s)\n",
      rc.damping_factor, rc.damping_factor_sigma, rc.damping_refuted ? 1 : 0, wc.damping_factor,
      wc.damping_factor_sigma, wc.damping_refuted ? 1 : 0, wc.damping_refuted_s);
  CHECK(seed.fit_comp.ok && right.fit_comp.ok && wrong.fit_comp.ok);
  // The seed's model alone takes the thermal change of nu (nu beta dT, 1.3e-5
  // 1/s, ~4 deg/h of bias at 4theta, seen by windows at other temperatures)
  // partly for anisotropy; the right coefficient removes at least two thirds
  // of what it leaves (measured: 1.91 -> 0.52 deg/h, clean 0.53). Its check
  // sees the change it predicts (f = 1 within 4 sigma) and keeps it.
  CHECK(right.compensation_valid);
  CHECK(right_comp < seed_comp / 3.0);
  CHECK(rc.damping_model && !rc.damping_refuted);
  CHECK(std::fabs(rc.damping_factor - 1.0) < 4.0 * rc.damping_factor_sigma);
  DOUBLES_EQUAL(kBetaPerC, right.final_calibration.thermal_damping_per_c, 0.0);
  // Do no harm: with the sign wrong the decays show the opposite of the
  // predicted change (f = -1 within 4 sigma); the check refutes the damping
  // model, the firmware takes it out and uses the seed's model identified
  // beside it from the same windows, so the output is the seed model's
  // (measured 1.91, as without the file) instead of 3.93 deg/h.
  CHECK(wc.damping_refuted);
  CHECK(std::fabs(wc.damping_factor + 1.0) < 4.0 * wc.damping_factor_sigma);
  DOUBLES_EQUAL(0.0, wrong.final_calibration.thermal_damping_per_c, 0.0);
  CHECK(wrong.compensation_valid);
  DOUBLES_EQUAL(seed_comp, wrong_comp, 0.1 * seed_comp);
  CHECK(raw > 20.0 * right_comp);
}

TEST(ThermalLoop, WithoutACoefficientTheDampingCheckReadsItThroughItsProbe) {
  // GIVEN no calibration: the check tries a thermal damping of 0.01 /degC
  // about the reference temperature (nothing applied)
  const RunResult seed = with_coefficient(0.0);
  const hrg::sim_run::FirmwareEstimates& e = seed.firmware_estimates;
  std::printf("thermal damping read without a coefficient: %.5f +- %.5f /degC\n",
              e.thermal_damping_per_c, e.thermal_damping_sigma_per_c);
  // THEN it reads the truth (4 sigma), finer than the audit on the same
  // telemetry (measured 0.00429 +- 0.00030 against the audit's 0.00433 +-
  // 0.00054)
  CHECK_TRUE(e.thermal_damping);
  DOUBLES_EQUAL(kBetaPerC, e.thermal_damping_per_c, 4.0 * e.thermal_damping_sigma_per_c);
  CHECK(e.thermal_damping_sigma_per_c > 0.0 && e.thermal_damping_sigma_per_c < 4e-4);
  // ... and the guard judges nothing: no damping part is in force
  CHECK_FALSE(seed.calibration.damping_model);
  CHECK_FALSE(seed.calibration.damping_refuted);
}
