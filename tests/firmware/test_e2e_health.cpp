// SPDX-License-Identifier: MIT
// Do no harm, reported: why the compensation is not valid reaches the
// report, the telemetry and the CAN bus from the one place the firmware
// builds it (Gyro::check_model), and D_Phi is withheld where the readout's
// own 4 theta pattern explains what its fits read.
//
// The 4.2 kHz resonator of tools/gregory/README.md with a 1 % y pickoff gain,
// no calibration, 1800 s: the model takes the gain's level pattern, read
// while the table turns, for damping anisotropy (22.7 standard errors from
// the pickoff self-identification's), and the pump's D_Phi fit reads it as
// a gap harmonic of 0.18-0.36 at 8-11 of its sigmas: -9.04 deg/h of mean
// D_Phi/K added before. A real gap (eps_p 0.02, eps_q 0.01) leaves no pattern
// in the free decays' level: its D_Phi stays applied.
//
// On the same resonator, 1800 s, seed 1, the seed model alone was reported
// valid worse than raw in two runs: a 1 deg phase lag, whose drift 2 nu phi
// no model holds (21.4 deg/h against 6.49 raw), and a -2 % gain, whose
// readout checks said 0 because the self-identification's decay test
// refused one decay rate (64.1 against 18.2). Both are now not valid.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "can/can_decode.hpp"
#include "firmware/compensation_reason.hpp"
#include "recording/recording.hpp"
#include "sim_run/report.hpp"
#include "sim_run/run.hpp"
#include "sim_run/scenario_run.hpp"

#include "support/default_scenario.hpp"
#include "support/cpputest.hpp"

TEST_GROUP_WITHOUT_LEAK_CHECK(Health);

namespace {

using hrg::fw::CompensationReason;
using hrg::fw::reason_bit;
using hrg::sim_run::RunConfig;
using hrg::sim_run::RunResult;

std::string source_dir() {
  const char* src = std::getenv("HRG_SOURCE_DIR");
  return src ? src : ".";
}

// tools/gregory/other-resonator.toml (4.2 kHz, Q 8e6, dmu 0.03 at 25 deg).
RunConfig other_resonator(double duration_s) {
  hrg::sim_run::ScheduleOptions o;
  o.duration_s = duration_s;
  return hrg::sim_run::run_from_scenario(source_dir() + "/tools/gregory/other-resonator.toml", o);
}

// A number of report.json's "compensation" object, by key.
double report_number(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const auto at = json.find(k, json.find("\"compensation\""));
  CHECK_TEXT(at != std::string::npos, key.c_str());
  return std::strtod(json.c_str() + at + k.size(), nullptr);
}

// The run's gap: D_Phi added, none withheld, nothing against the compensation.
void check_gap_keeps_its_d_phi(RunConfig j) {
  j.sim.electrodes.eps_p = 0.02;
  j.sim.electrodes.eps_q = 0.01;
  const RunResult r = hrg::sim_run::run_simulation(j, {});
  std::printf("\n  gap: D_Phi/K added %+.4f deg/h, withheld %+.4f, readout %.2f / %.2f sigma",
              r.control_drift_mean_dph, r.control_drift_withheld_mean_dph, r.readout_damping_sigmas,
              r.readout_pattern_sigmas);
  // nu |eps| / 2 over K: about 1-2 deg/h of mean D_Phi/K on these resonators
  CHECK(r.pump_drift_usable);
  CHECK(r.control_drift_mean_dph > 0.5);
  DOUBLES_EQUAL(0.0, r.control_drift_withheld_mean_dph, 0.0);
  CHECK(r.compensation_valid);
  LONGS_EQUAL(0, r.compensation_reasons);
}

}  // namespace

TEST(Health, AGainTakenForDampingIsReportedWithItsFigureInTheReportTelemetryAndOnTheBus) {
  // GIVEN the 1 % gain on the 4.2 kHz resonator, 1800 s, its CAN log kept
  RunConfig j = other_resonator(1800.0);
  j.sim.effects.pickoff_gain_mismatch.enabled = true;
  j.sim.effects.pickoff_gain_mismatch.gain = 0.01;
  // The long-run plan's still-base check refutes this model first (check
  // failed in the first park, the compensation withdrawn before D_Phi is
  // used: reasons 0x72, nothing added or withheld); the
  // readout check is what keeps it not valid where the base never rests for
  // a window period, and that is the path followed here.
  j.firmware.gyro.windows.still_rate_average_frames = 0;
  hrg::sim_run::RunOptions opt;
  opt.can_log = "test_e2e_health.log";
  const RunResult r = hrg::sim_run::run_simulation(j, opt);
  std::printf(
      "\n  gain: readout %.2f sigma, reasons 0x%02x, D_Phi/K added %+.4f withheld %+.4f "
      "deg/h, pump gap %.3f at %.1f sigma",
      r.readout_damping_sigmas, r.compensation_reasons, r.control_drift_mean_dph,
      r.control_drift_withheld_mean_dph, r.pump_gap, r.pump_gap_sigmas);
  // THEN the check trips: the model's dnu_S 8.4e-5 1/s from the
  // self-identification's, many times both sigmas (~4e-6)
  const uint8_t want = reason_bit(CompensationReason::readout_in_damping) |
                       reason_bit(CompensationReason::control_drift_withheld);
  CHECK(r.readout_damping_sigmas > 2.0 * j.firmware.gyro.max_readout_damping_sigmas);
  CHECK_FALSE(r.compensation_valid);
  LONGS_EQUAL(want, r.compensation_reasons & want);
  // AND D_Phi, its fit reading the gain as a gap harmonic, is withheld, not
  // added (its fit was in use: a withheld drift is one it computed; the
  // model's withdrawal by a later check ends its use before the run's end)
  DOUBLES_EQUAL(0.0, r.control_drift_mean_dph, 0.0);
  CHECK(std::fabs(r.control_drift_withheld_mean_dph) > 1.0);
  // AND report.json carries the figure and the reasons
  const std::string json = hrg::sim_run::report_json(j, r);
  DOUBLES_EQUAL(r.readout_damping_sigmas, report_number(json, "readout_damping_sigmas"), 1e-6);
  LONGS_EQUAL(r.compensation_reasons, std::lround(report_number(json, "reason_bits")));
  CHECK(json.find("\"readout_in_damping\"") != std::string::npos);
  // AND the last telemetry row, and the CAN log decoded with the DBC, end on them
  const hrg::recording::Recording tm = hrg::sim_run::telemetry_recording(j, r);
  const std::size_t last = tm.rows() - 1;
  DOUBLES_EQUAL(r.readout_damping_sigmas, tm.column("readout_damping_sigmas")[last], 1e-9);
  DOUBLES_EQUAL(r.compensation_reasons, tm.column("comp_reasons")[last], 0.0);
  hrg::can::CanDecodeOptions o;
  o.log_path = opt.can_log;
  o.out_path = "test_e2e_health.csv";
  o.dbc_path = source_dir() + "/firmware/can/hrg.dbc";
  (void)hrg::can::can_decode(o);
  const hrg::recording::Recording bus = hrg::recording::read_recording(o.out_path);
  const std::size_t end = bus.rows() - 1;
  DOUBLES_EQUAL(r.readout_damping_sigmas, bus.column("readout_damping_sigmas")[end], 0.25);
  DOUBLES_EQUAL(r.compensation_reasons, bus.column("comp_reasons")[end], 0.0);
  DOUBLES_EQUAL(0.0, bus.column("comp_valid")[end], 0.0);
  std::remove(opt.can_log.c_str());
  std::remove(o.out_path.c_str());
}

TEST(Health, AOneDegreePhaseLagLeftInTheReadoutMakesTheSeedModelNotValid) {
  // GIVEN the 4.2 kHz resonator with a 1 deg y pickoff phase, no calibration,
  // 1800 s, seed 1: the seed's model alone was reported valid at 21.4 deg/h
  // against 6.49 raw (its check window's misfit 0.372, inside 1/4 ... 4)
  RunConfig j = other_resonator(1800.0);
  j.sim.effects.pickoff_phase_mismatch.enabled = true;
  j.sim.effects.pickoff_phase_mismatch.phase_deg = 1.0;
  const RunResult r = hrg::sim_run::run_simulation(j, {});
  std::printf("\n  phase 1 deg: %.1f sigma, drift share %.3f, reasons 0x%02x",
              r.readout_phase_sigmas, r.readout_phase_drift_share, r.compensation_reasons);
  // THEN the self-identification's phase stands thousands of sigmas out and
  // its drift 2 nu phi (5.76e-5 rad/s) is more than the model's |dnu|
  // (4.95e-5 1/s): share 1.16, above 1/2
  CHECK(r.readout_phase_sigmas > 1000.0);
  DOUBLES_EQUAL(1.16, r.readout_phase_drift_share, 0.05);
  // AND the compensation is never valid, for that reason, in the report too
  CHECK_FALSE(r.compensation_valid);
  const uint8_t phase = reason_bit(CompensationReason::readout_phase_drift);
  LONGS_EQUAL(phase, r.compensation_reasons & phase);
  const std::string json = hrg::sim_run::report_json(j, r);
  CHECK(json.find("\"readout_phase_drift\"") != std::string::npos);
  DOUBLES_EQUAL(r.readout_phase_drift_share, report_number(json, "readout_phase_drift_share"),
                1e-6);
}

TEST(Health, AGainOfMinusTwoPercentIsSeenByTheReadoutChecks) {
  // GIVEN the 4.2 kHz resonator with a -2 % y pickoff gain, no calibration,
  // 1800 s, seed 1: the seed's model was reported valid at 64.1 deg/h against
  // 18.2 raw. The self-identification's decay test refused one decay rate
  // there (F 1.98 > 1.70) while its level model stopped at u^2/2 and left
  // out the damping's cross term with the map; with them one rate holds
  // (F 0.99), and the common fit speaks.
  RunConfig j = other_resonator(1800.0);
  j.sim.effects.pickoff_gain_mismatch.enabled = true;
  j.sim.effects.pickoff_gain_mismatch.gain = -0.02;
  const RunResult r = hrg::sim_run::run_simulation(j, {});
  std::printf("\n  gain -0.02: decay F %.2f, readout %.1f / %.0f sigma, reasons 0x%02x",
              r.self_calibration.decay_f, r.readout_damping_sigmas, r.readout_pattern_sigmas,
              r.compensation_reasons);
  CHECK_TRUE(r.self_calibration.decay_consistent);
  // THEN the self-identification reads the gain thousands of sigmas out,
  // and the model's dnu_S (-1.19e-4 1/s) many sigmas from its (truth 4.87e-5)
  CHECK(r.readout_pattern_sigmas > 1000.0);
  CHECK(r.readout_damping_sigmas > 2.0 * j.firmware.gyro.max_readout_damping_sigmas);
  // AND the compensation is not valid: the readout is in the damping
  CHECK_FALSE(r.compensation_valid);
  const uint8_t damping = reason_bit(CompensationReason::readout_in_damping);
  LONGS_EQUAL(damping, r.compensation_reasons & damping);
}

TEST(Health, TheGapsDPhiStaysAppliedOnTheOtherResonator) {
  check_gap_keeps_its_d_phi(other_resonator(0.0));
}

TEST(Health, TheGapsDPhiStaysAppliedOnTheDefaultScenario) {
  check_gap_keeps_its_d_phi(hrg::test::default_scenario_run());
}
