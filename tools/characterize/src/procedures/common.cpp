// SPDX-License-Identifier: MIT
#include "common.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sim_tools/analysis.hpp"
#include "sim_tools/scenario_job.hpp"

namespace hrg::characterize {

ProcedureBase procedure_base(const ProcedureOptions& o) {
  ProcedureBase b;
  b.job = simtools::make_job(o.scenario, simtools::ScheduleOptions{});
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
  table.hold(simtools::kRingUpS);
  table.turn(simtools::sweep_case_rad(angular_gain), 10.0 * kDeg, 1.0);
  table.hold(2.0);
  sweep_end_s = table.t;
}

void Schedule::set_rate(double rate_rad_s, double ramp_s) {
  table.t += ramp_s;
  table.pts.push_back({table.t, rate_rad_s});
}

simtools::JobConfig scheduled_job(const ProcedureBase& base, const Schedule& schedule) {
  simtools::JobConfig job = base.job;
  job.sim.rate_rad_s = schedule.table.profile(base.earth_rad_s);
  job.parks.clear();
  job.duration_s = schedule.t();
  job.sweep_end_s = schedule.sweep_end_s;
  return job;
}

simtools::JobResult run_alone(const simtools::JobConfig& job, const ProcedureOptions& o) {
  simtools::RunOptions opt;
  opt.progress = o.progress;
  return simtools::run_job(job, opt);
}

simtools::JobResult run(const simtools::JobConfig& job, const ProcedureOptions& o, double& wall_s,
                        double& sim_s) {
  simtools::JobResult r = run_alone(job, o);
  wall_s += r.wall_s;
  sim_s += r.sim_s;
  return r;
}

double rate_of(const std::vector<simtools::TelemetryRow>& rows,
               double simtools::TelemetryRow::*column, double t0_s, double t1_s) {
  std::vector<double> t, y;
  for (const simtools::TelemetryRow& row : rows) {
    if (row.t_s < t0_s || row.t_s > t1_s || !row.out_valid) continue;
    t.push_back(row.t_s);
    y.push_back(row.*column);
  }
  return t.size() < 3 ? 0.0 : simtools::slope(t, y);
}

const simtools::TelemetryRow& row_at(const std::vector<simtools::TelemetryRow>& rows, double t_s) {
  if (rows.empty()) throw std::logic_error("procedure: no telemetry rows");
  const auto it =
      std::lower_bound(rows.begin(), rows.end(), t_s,
                       [](const simtools::TelemetryRow& r, double t) { return r.t_s < t; });
  if (it == rows.end()) return rows.back();
  if (it != rows.begin() && std::fabs(std::prev(it)->t_s - t_s) < std::fabs(it->t_s - t_s))
    return *std::prev(it);
  return *it;
}

double value_at(const std::vector<simtools::TelemetryRow>& rows,
                double simtools::TelemetryRow::*column, double t_s) {
  if (rows.size() < 2) throw std::logic_error("procedure: too few telemetry rows");
  auto it = std::lower_bound(rows.begin(), rows.end(), t_s,
                             [](const simtools::TelemetryRow& r, double t) { return r.t_s < t; });
  if (it == rows.begin()) ++it;
  if (it == rows.end()) --it;
  const simtools::TelemetryRow& a = *std::prev(it);
  const simtools::TelemetryRow& b = *it;
  const double w = (t_s - a.t_s) / (b.t_s - a.t_s);
  return a.*column + w * (b.*column - a.*column);
}

MeanRates mean_rates(const std::vector<simtools::TelemetryRow>& rows,
                     double simtools::TelemetryRow::*column, double t0_s, double t1_s) {
  const double dt = t1_s - t0_s;
  const auto delta = [&](double simtools::TelemetryRow::*c) {
    return value_at(rows, c, t1_s) - value_at(rows, c, t0_s);
  };
  return {delta(&simtools::TelemetryRow::true_angle_deg) * kDeg / dt, delta(column) * kDeg / dt};
}

}  // namespace proc
}  // namespace hrg::characterize
