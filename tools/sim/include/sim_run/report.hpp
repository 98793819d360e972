// SPDX-License-Identifier: MIT
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "recording/recording.hpp"
#include "sim_run/run.hpp"

namespace hrg::sim_run {

// report.json: realtime_factor, excitation_off_fraction, drift.{raw,compensated}
// .{adb_dph, mean_dph}, identification (estimate, sigma, truth per parameter),
// executive (per task max time and overruns), checks.
std::string report_json(const RunConfig& job, const RunResult& r);

// How a long run's telemetry file is kept small: every decimate-th row only
// (the metadata says so), and a new file every rotate_s simulated seconds
// (telemetry-000.csv, telemetry-001.csv, ...; 0: one file).
struct TelemetryFileOptions {
  std::size_t decimate = 1;
  double rotate_s = 0.0;
};

// telemetry.csv: hrg-recording v1 plus theta_deg, out_angle_deg,
// true_angle_deg, mode and the truth columns. Returns the files written.
std::vector<std::filesystem::path> write_telemetry(const std::filesystem::path& path,
                                                   const RunConfig& job, const RunResult& r,
                                                   const TelemetryFileOptions& o = {});
// The same telemetry as a recording in memory.
recording::Recording telemetry_recording(const RunConfig& job, const RunResult& r);

// bias.csv (one row per parked angle) and allan.csv (tau, adev) for the plots.
void write_bias_csv(const std::filesystem::path& path, const RunResult& r);
void write_allan_csv(const std::filesystem::path& path, const RunResult& r);

// The end-of-run summary table.
void print_summary(std::FILE* out, const RunConfig& job, const RunResult& r);

// The simulated target's share of a lockstep run, the figure held to the
// issue-13 goal (by CPU time over the unpreempted stretches) and the
// wall-clock one beside it, e.g. "38 % by CPU time (97 % of 64-block
// stretches unpreempted); 41 % by wall time".
std::string describe_share(const RunResult& r);

// How many parks the compensated bias was measured on (the model valid
// throughout), since when, and the run length the resonator needs.
std::string bias_test_coverage(const RunResult& r);

// A parked-angle set too narrow for the 4 theta fit (BiasFit::degenerate):
// the parks' angle span, the fit's condition and the mean bias over them.
std::string degenerate_parks_note(const BiasFit& f);

// Fills r.failures with what makes the run a failure (see the checks in
// report_json); returns true when the run passed.
bool judge(const RunConfig& job, RunResult& r);

}  // namespace hrg::sim_run
