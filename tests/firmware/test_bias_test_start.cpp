// SPDX-License-Identifier: MIT
// The main job's bias test against the firmware's own word (issue 19): the
// compensated bias is measured only on parks where the firmware reported its
// model valid, and a resonator that converges late is reported as not
// measured with the run length it needs, not as "no compensation". And the
// control-loop drift D_Phi adds nothing on an ideal ring electrode: its mean
// stays below the resonator model's own bias uncertainty, for the seed's,
// a navigation-grade and a relaxed resonator.
#include <cmath>
#include <numbers>
#include <string>

#include "sim_run/run.hpp"
#include "sim_run/report.hpp"

#include "support/cpputest.hpp"

namespace {
using hrg::sim_run::RunConfig;
using hrg::sim_run::RunResult;

constexpr double kRadSToDph = 180.0 / std::numbers::pi * 3600.0;

// The default 365 s job with another resonator (ideal electrode, default ADC).
RunConfig job_with(double q, double dmu, double split_hz) {
  RunConfig j = hrg::sim_run::default_run(0.0, 16);
  j.sim.resonator.q = q;
  j.sim.resonator.dmu = dmu;
  j.sim.resonator.split_hz = split_hz;
  j.firmware.chain.q_factor = q;
  hrg::sim_run::derive_firmware_config(j);
  return j;
}

// The model's own uncertainty on the angle-dependent bias: the sigma of the
// damping anisotropy terms as input rate (deg/h).
double model_bias_sigma_dph(const RunResult& r, const RunConfig& j) {
  return std::hypot(r.identification.sigma[1], r.identification.sigma[2]) /
         j.firmware.gyro.angular_gain * kRadSToDph;
}

void check_no_control_drift(double q, double dmu, double split_hz) {
  const RunConfig j = job_with(q, dmu, split_hz);
  const RunResult r = hrg::sim_run::run_simulation(j, {});
  const double sigma_dph = model_bias_sigma_dph(r, j);
  CHECK(sigma_dph > 0.0);
  CHECK(std::fabs(r.control_drift_mean_dph) < sigma_dph);
}
}  // namespace

TEST_GROUP_WITHOUT_LEAK_CHECK(BiasTestStart);

TEST(BiasTestStart, ASlowConvergingResonatorIsReportedNotMeasuredWithTheLengthItNeeds) {
  // GIVEN the relaxed resonator (Q 1e6, dmu 0.15, split 5e-3 Hz), whose
  // identification ends well after the sweep (the parks start at ~110 s)
  RunConfig j = job_with(1.0e6, 0.15, 5.0e-3);
  RunResult r = hrg::sim_run::run_simulation(j, {});
  // THEN the parks before the model was valid are not in the compensated fit
  CHECK(r.t_model_valid_s > j.parks.front().t_begin_s);
  CHECK(r.parks_model_valid < r.parks.size());
  for (const auto& p : r.parks)
    CHECK(!p.model_valid || r.t_model_valid_s >= 0.0);
  // and with fewer than 4 such parks no compensated figure is reported
  // (not 857 deg/h "compensated" from the raw angle), the run fails naming
  // a length at least the wait longer.
  CHECK(r.parks_model_valid >= 4 || !r.fit_comp.ok);
  CHECK(r.bias_test_needs_s >= j.duration_s + r.t_model_valid_s - j.parks.front().t_begin_s - 1);
  CHECK_FALSE(hrg::sim_run::judge(j, r));
  bool named = false;
  for (const auto& f : r.failures)
    named = named || f.find("needs a run of at least") != std::string::npos;
  CHECK(named);
  // The raw figure is still measured on every park.
  CHECK(r.fit_raw.ok);
  CHECK(r.fit_raw.amplitude() > 500.0);
}

TEST(BiasTestStart, TheDefaultRunsParksAreMostlyMeasuredWithTheModelValid) {
  RunConfig j = hrg::sim_run::default_run(0.0, 16);
  RunResult r = hrg::sim_run::run_simulation(j, {});
  CHECK(r.parks_model_valid >= 12);
  CHECK(r.fit_comp.ok);
  CHECK(hrg::sim_run::judge(j, r));
}

TEST_GROUP_WITHOUT_LEAK_CHECK(ControlDriftGate);

TEST(ControlDriftGate, SeedResonatorIdealElectrodeAddsLessThanTheModelsOwnUncertainty) {
  check_no_control_drift(5.0e6, 0.05, 5.0e-4);
}

TEST(ControlDriftGate, NavigationGradeResonatorIdealElectrodeAddsLessThanTheModelsOwnUncertainty) {
  // Before the gate: +0.70 deg/h of mean D_Phi (fitted gap 1e-2 from noise).
  check_no_control_drift(2.0e7, 0.005, 1.0e-4);
}

TEST(ControlDriftGate, RelaxedResonatorIdealElectrodeAddsLessThanTheModelsOwnUncertainty) {
  check_no_control_drift(1.0e6, 0.15, 5.0e-3);
}
