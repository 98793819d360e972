// SPDX-License-Identifier: MIT
// The firmware's own reading of the pickoff map in the recording it writes
// (self_cal_* keys, tools/audit/README.md "--calibration"), on the main job
// (default scenario, 365 s, a 1 deg y phase lag): the keys are report.json's
// whole map, referred to the raw pickoffs whatever map is in force, and the
// audit reads the phase in the same convention, so `hrg audit --calibration`
// weighs the two into a file value between them.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "audit/audit.hpp"
#include "audit/calibration_writer.hpp"
#include "audit/firmware_estimates.hpp"
#include "estimator/pickoff_evidence.hpp"
#include "recording/recording.hpp"
#include "sim_run/report.hpp"
#include "sim_run/run.hpp"
#include "sim_run/scenario_run.hpp"

#include "support/default_scenario.hpp"
#include "support/cpputest.hpp"

TEST_GROUP_WITHOUT_LEAK_CHECK(PickoffReadings);

namespace {

using hrg::sim_run::RunConfig;
using hrg::sim_run::RunResult;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kPhaseRad = 1.0 * kDeg;

RunConfig phase_lag() {
  RunConfig j = hrg::test::default_scenario_run();
  j.sim.effects.pickoff_phase_mismatch.enabled = true;
  j.sim.effects.pickoff_phase_mismatch.phase_deg = kPhaseRad / kDeg;
  return j;
}

double header(const hrg::recording::Recording& rec, const char* key) {
  const std::string v = rec.metadata_value(key);
  CHECK_TEXT(!v.empty(), key);
  return v.empty() ? 0.0 : std::stod(v);
}

const hrg::audit::Finding* finding(const hrg::audit::AuditResult& a, hrg::audit::Effect e) {
  for (const auto& f : a.findings)
    if (f.effect == e) return &f;
  return nullptr;
}

}  // namespace

TEST(PickoffReadings, TheAuditAndTheFirmwareReadThePhaseInOneConventionAndTheFileWeighsThem) {
  // GIVEN a 1 deg y phase lag and no calibration (the map in force: none)
  const RunConfig j = phase_lag();
  const RunResult r = hrg::sim_run::run_simulation(j, {});
  const hrg::recording::Recording rec = hrg::sim_run::telemetry_recording(j, r);
  // THEN the header holds the firmware's whole map, exactly report.json's
  // (est::whole_estimate of its last solve through the identity)
  const auto& e = r.firmware_estimates;
  CHECK_TRUE(e.pickoff);
  const hrg::est::PickoffMapEstimate m = hrg::est::whole_estimate({}, r.self_calibration);
  DOUBLES_EQUAL(m.value.phase_rad, e.pickoff_phase_rad, 0.0);
  DOUBLES_EQUAL(e.pickoff_gain, header(rec, "self_cal_gain"), 0.0);
  DOUBLES_EQUAL(e.pickoff_gain_sigma, header(rec, "self_cal_gain_sigma"), 0.0);
  DOUBLES_EQUAL(e.pickoff_misalignment_rad, header(rec, "self_cal_misalignment_rad"), 0.0);
  DOUBLES_EQUAL(e.pickoff_misalignment_sigma_rad, header(rec, "self_cal_misalignment_sigma_rad"),
                0.0);
  DOUBLES_EQUAL(e.pickoff_phase_rad, header(rec, "self_cal_phase_rad"), 0.0);
  DOUBLES_EQUAL(e.pickoff_phase_sigma_rad, header(rec, "self_cal_phase_sigma_rad"), 0.0);
  // ... the truth, with its sign, within 5 of its sigmas
  DOUBLES_EQUAL(kPhaseRad, e.pickoff_phase_rad, 5.0 * e.pickoff_phase_sigma_rad);
  // WHEN the recording is audited
  const hrg::audit::AuditResult a = hrg::audit::run_audit(rec);
  const hrg::audit::Finding* f = finding(a, hrg::audit::Effect::pickoff_phase_mismatch);
  CHECK_TEXT(f != nullptr, hrg::audit::to_text(a, "sim").c_str());
  // THEN it reads the same phase, y lagging x by +1 deg at the raw pickoffs:
  // the two within 5 sigma of each other (a sign or reference apart would
  // be 2 deg or 1 deg, thousands of sigmas)
  const double sa = f->sigma * kDeg;
  const double sf = e.pickoff_phase_sigma_rad;
  DOUBLES_EQUAL(kPhaseRad, f->value * kDeg, 5.0 * sa);
  DOUBLES_EQUAL(f->value * kDeg, e.pickoff_phase_rad, 5.0 * std::hypot(sa, sf));
  // AND the file weighs them: between the two, its sigma below both
  hrg::audit::CalibrationWriterOptions opt;
  opt.firmware = hrg::audit::firmware_estimates(rec, "sim");
  const auto c = hrg::audit::calibration_from_audit(a, "sim", opt);
  const double phi = c.file.calibration.pickoff_y_phase_rad;
  CHECK(phi >= std::fmin(f->value * kDeg, e.pickoff_phase_rad));
  CHECK(phi <= std::fmax(f->value * kDeg, e.pickoff_phase_rad));
  CHECK(c.file.sigma[1] < std::fmin(sa, sf));  // pickoff_y_phase_rad
}

namespace {

// A run of the 1 deg lag with `in_force_rad` of it in the file.
RunResult with_phase_in_force(double in_force_rad) {
  RunConfig j = phase_lag();
  j.firmware.calibration.pickoff_y_phase_rad = in_force_rad;
  const RunResult r = hrg::sim_run::run_simulation(j, {});
  std::printf(
      "\n  %.2f deg in the file: %s, in force %.6f deg, residual %.6f +- %.6f, "
      "whole %.6f +- %.6f deg\n",
      in_force_rad / kDeg, hrg::fw::app::to_string(r.calibration.verdict),
      r.final_calibration.pickoff_y_phase_rad / kDeg, r.self_calibration.phase_rad / kDeg,
      r.self_calibration.phase_sigma_rad / kDeg, r.firmware_estimates.pickoff_phase_rad / kDeg,
      r.firmware_estimates.pickoff_phase_sigma_rad / kDeg);
  const hrg::recording::Recording rec = hrg::sim_run::telemetry_recording(j, r);
  DOUBLES_EQUAL(r.firmware_estimates.pickoff_phase_rad, header(rec, "self_cal_phase_rad"), 0.0);
  return r;
}

}  // namespace

TEST(PickoffReadings, WithTheMapInForceTheKeysStillReadTheRawPickoffs) {
  // GIVEN the true lag in the file, kept
  const RunResult r = with_phase_in_force(kPhaseRad);
  CHECK(r.calibration.verdict != hrg::fw::app::CalibrationVerdict::withdrawn);
  DOUBLES_EQUAL(kPhaseRad, r.final_calibration.pickoff_y_phase_rad, 0.0);
  // THEN the self-calibration's residual is ~0, and the keys the whole lag
  // (the map in force composed with it)
  const auto& e = r.firmware_estimates;
  CHECK_TRUE(e.pickoff);
  DOUBLES_EQUAL(0.0, r.self_calibration.phase_rad, 5.0 * r.self_calibration.phase_sigma_rad);
  DOUBLES_EQUAL(kPhaseRad + r.self_calibration.phase_rad, e.pickoff_phase_rad, 1e-15);
  DOUBLES_EQUAL(kPhaseRad, e.pickoff_phase_rad, 5.0 * e.pickoff_phase_sigma_rad);
}

TEST(PickoffReadings, AfterAMapIsWithdrawnTheKeysStillReadTheRawPickoffs) {
  // GIVEN half the lag in the file: its first check window disagrees and it
  // is withdrawn, the chain back on the raw pickoffs
  const RunResult r = with_phase_in_force(0.5 * kPhaseRad);
  CHECK(r.calibration.verdict == hrg::fw::app::CalibrationVerdict::withdrawn);
  DOUBLES_EQUAL(0.0, r.final_calibration.pickoff_y_phase_rad, 0.0);
  // THEN the windows read through the half before it went are re-referred:
  // the reading is the whole lag (before, the two kinds of window mixed
  // read 0.657 +- 0.003 deg)
  const auto& e = r.firmware_estimates;
  CHECK_TRUE(e.pickoff);
  DOUBLES_EQUAL(kPhaseRad, e.pickoff_phase_rad, 5.0 * e.pickoff_phase_sigma_rad);
}
