// SPDX-License-Identifier: MIT
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "recording/recording.hpp"
#include "sim_tools/job.hpp"

namespace hrg::simtools {

// report.json: realtime_factor, excitation_off_fraction, drift.{raw,compensated}
// .{adb_dph, mean_dph}, identification (estimate, sigma, truth per parameter),
// executive (per task max time and overruns), checks.
std::string report_json(const JobConfig& job, const JobResult& r);

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
                                                   const JobConfig& job, const JobResult& r,
                                                   const TelemetryFileOptions& o = {});
// The same telemetry as a recording in memory.
recording::Recording telemetry_recording(const JobConfig& job, const JobResult& r);

// bias.csv (one row per parked angle) and allan.csv (tau, adev) for the plots.
void write_bias_csv(const std::filesystem::path& path, const JobResult& r);
void write_allan_csv(const std::filesystem::path& path, const JobResult& r);

// The end-of-run summary table.
void print_summary(std::FILE* out, const JobConfig& job, const JobResult& r);

// How many parks the compensated bias was measured on (the model valid
// throughout), since when, and the run length the resonator needs.
std::string bias_test_coverage(const JobResult& r);

// Fills r.failures with what makes the run a failure (see the checks in
// report_json); returns true when the run passed.
bool judge(const JobConfig& job, JobResult& r);

}  // namespace hrg::simtools
