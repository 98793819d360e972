// SPDX-License-Identifier: MIT
#include "common.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sim_run/analysis.hpp"
#include "sim_run/scenario_run.hpp"

namespace hrg::characterize {

ProcedureBase procedure_base(const ProcedureOptions& o) {
  ProcedureBase b;
  b.job = sim_run::make_run(o.scenario, sim_run::ScheduleOptions{});
  if (!o.scenario.empty() && b.job.parks.empty()) {
    throw std::invalid_argument("scenario " + o.scenario +
                                ": the test procedures drive the rate table themselves; give the "
                                "scenario a constant rate (the Earth rate)");
  }
  b.earth_rad_s = b.job.earth_rate_rad_s;
  return b;
}

namespace proc {

Schedule::Schedule(double angular_gain) {
  table.hold(sim_run::kRingUpS);
  table.turn(sim_run::sweep_case_rad(angular_gain), 10.0 * kDeg, 1.0);
  table.hold(2.0);
  sweep_end_s = table.t;
}

void Schedule::set_rate(double rate_rad_s, double ramp_s) {
  table.t += ramp_s;
  table.pts.push_back({table.t, rate_rad_s});
}

sim_run::RunConfig scheduled_job(const ProcedureBase& base, const Schedule& schedule) {
  sim_run::RunConfig job = base.job;
  job.sim.rate_rad_s = schedule.table.profile(base.earth_rad_s);
  job.parks.clear();
  job.duration_s = schedule.t();
  job.sweep_end_s = schedule.sweep_end_s;
  return job;
}

sim_run::RunResult run_alone(const sim_run::RunConfig& job, const ProcedureOptions& o) {
  sim_run::RunOptions opt;
  opt.progress = o.progress;
  return sim_run::run_simulation(job, opt);
}

sim_run::RunResult run(const sim_run::RunConfig& job, const ProcedureOptions& o, double& wall_s,
                       double& sim_s) {
  sim_run::RunResult r = run_alone(job, o);
  wall_s += r.wall_s;
  sim_s += r.sim_s;
  return r;
}

double rate_of(const std::vector<sim_run::TelemetryRow>& rows,
               double sim_run::TelemetryRow::*column, double t0_s, double t1_s) {
  std::vector<double> t, y;
  for (const sim_run::TelemetryRow& row : rows) {
    if (row.t_s < t0_s || row.t_s > t1_s || !row.out_valid) continue;
    t.push_back(row.t_s);
    y.push_back(row.*column);
  }
  return t.size() < 3 ? 0.0 : sim_run::slope(t, y);
}

const sim_run::TelemetryRow& row_at(const std::vector<sim_run::TelemetryRow>& rows, double t_s) {
  if (rows.empty()) throw std::logic_error("procedure: no telemetry rows");
  const auto it =
      std::lower_bound(rows.begin(), rows.end(), t_s,
                       [](const sim_run::TelemetryRow& r, double t) { return r.t_s < t; });
  if (it == rows.end()) return rows.back();
  if (it != rows.begin() && std::fabs(std::prev(it)->t_s - t_s) < std::fabs(it->t_s - t_s))
    return *std::prev(it);
  return *it;
}

double value_at(const std::vector<sim_run::TelemetryRow>& rows,
                double sim_run::TelemetryRow::*column, double t_s) {
  if (rows.size() < 2) throw std::logic_error("procedure: too few telemetry rows");
  auto it = std::lower_bound(rows.begin(), rows.end(), t_s,
                             [](const sim_run::TelemetryRow& r, double t) { return r.t_s < t; });
  if (it == rows.begin()) ++it;
  if (it == rows.end()) --it;
  const sim_run::TelemetryRow& a = *std::prev(it);
  const sim_run::TelemetryRow& b = *it;
  const double w = (t_s - a.t_s) / (b.t_s - a.t_s);
  return a.*column + w * (b.*column - a.*column);
}

MeanRates mean_rates(const std::vector<sim_run::TelemetryRow>& rows,
                     double sim_run::TelemetryRow::*column, double t0_s, double t1_s) {
  const double dt = t1_s - t0_s;
  const auto delta = [&](double sim_run::TelemetryRow::*c) {
    return value_at(rows, c, t1_s) - value_at(rows, c, t0_s);
  };
  return {delta(&sim_run::TelemetryRow::true_angle_deg) * kDeg / dt, delta(column) * kDeg / dt};
}

}  // namespace proc
}  // namespace hrg::characterize
