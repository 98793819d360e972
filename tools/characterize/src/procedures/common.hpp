// SPDX-License-Identifier: MIT
// Pieces shared by the test procedures: the rate-table schedule after the
// identification sweep, one run through the main job's runner, and readings
// of the telemetry rows.
#pragma once

#include <numbers>
#include <vector>

#include "characterize/procedures.hpp"
#include "sim_run/table_schedule.hpp"

namespace hrg::characterize::proc {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kDph = kDeg / 3600.0;  // rad/s per deg/h

// The rate table: the job's ring-up and identification sweep (as the main
// job's default schedule), then what the procedure adds.
struct Schedule {
  sim_run::TableSchedule table;
  double sweep_end_s = 0.0;

  // Ring-up, the identification sweep (two 4 theta circles at 10 deg/s of
  // the case) and a short still hold, as in default_run.
  explicit Schedule(double angular_gain);
  // The table rate goes to `rate_rad_s` over `ramp_s` and stays there.
  void set_rate(double rate_rad_s, double ramp_s);
  // Holds the current rate for dt_s.
  void hold(double dt_s) { table.hold(dt_s); }
  double t() const { return table.t; }
};

// The job with `schedule` as its rate-table profile (plus the Earth rate),
// no parks, running to the end of the schedule.
sim_run::RunConfig scheduled_job(const ProcedureBase& base, const Schedule& schedule);

// Runs the job (firmware + simulated target in lockstep); run() adds its time.
// Each run has a simulated target of its own: runs may go on in parallel.
sim_run::RunResult run_alone(const sim_run::RunConfig& job, const ProcedureOptions& o);
sim_run::RunResult run(const sim_run::RunConfig& job, const ProcedureOptions& o, double& wall_s,
                       double& sim_s);

// Least-squares slope (per s) of `column` over rows in [t0_s, t1_s] with a
// valid output; 0 when fewer than 3 rows.
double rate_of(const std::vector<sim_run::TelemetryRow>& rows,
               double sim_run::TelemetryRow::*column, double t0_s, double t1_s);

// `column` at time t_s, linear between the two rows around it: a step's
// ends fall between rows, and over whole 4 theta cycles the readout's 4 theta
// error cancels only when both ends are read at the cycle's own instants.
double value_at(const std::vector<sim_run::TelemetryRow>& rows,
                double sim_run::TelemetryRow::*column, double t_s);

// The mean rate of `column` (per s) against that of the true input angle
// between t0_s and t1_s: {input, output}.
struct MeanRates {
  double input = 0.0, output = 0.0;
};
MeanRates mean_rates(const std::vector<sim_run::TelemetryRow>& rows,
                     double sim_run::TelemetryRow::*column, double t0_s, double t1_s);

// The row nearest time t_s.
const sim_run::TelemetryRow& row_at(const std::vector<sim_run::TelemetryRow>& rows, double t_s);

}  // namespace hrg::characterize::proc
