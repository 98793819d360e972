// SPDX-License-Identifier: MIT
// IEEE 1431 12.11 drift-rate series on the simulated gyro: the main job's
// parked-angle (angle-dependent bias) test, the bias over N turn-ons with
// different noise seeds, and the bias along a temperature ramp.
#include <cmath>

#include "batch/batch.hpp"
#include "common.hpp"
#include "sim_run/scenario_run.hpp"

namespace hrg::characterize {

namespace {

using proc::kDeg;
constexpr double kSettleS = 5.0;  // after the sweep, before the bias is read

// Bias of the output (deg/h): the slope of output minus true angle.
double bias_dph(const std::vector<sim_run::TelemetryRow>& rows,
                double sim_run::TelemetryRow::*error, double t0_s, double t1_s) {
  return proc::rate_of(rows, error, t0_s, t1_s) * 3600.0;
}

// The turn-ons differ by their noise seed alone and share nothing: they run
// o.jobs at a time and are read in turn-on order.
void turn_ons(const ProcedureOptions& o, const ProcedureBase& base, DriftResult& res) {
  const double hold_s = o.short_run ? 30.0 : 60.0;
  const auto n = static_cast<std::size_t>(o.turn_ons);
  std::vector<sim_run::RunConfig> jobs;
  double t0 = 0.0, t1 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    ProcedureBase b = base;
    b.job.sim.seed = base.job.sim.seed + 1 + i;
    proc::Schedule sch(b.job.firmware.gyro.angular_gain);
    t0 = sch.t() + kSettleS;
    sch.hold(kSettleS + hold_s);
    t1 = sch.t();
    jobs.push_back(proc::scheduled_job(b, sch));
  }
  ProcedureOptions one = o;
  one.progress = o.progress && (o.jobs == 1 || n <= 1);  // one bar at a time
  const std::vector<sim_run::RunResult> runs =
      batch::run_indexed(n, o.jobs, [&](std::size_t i) { return proc::run_alone(jobs[i], one); });
  for (const sim_run::RunResult& r : runs) {
    res.wall_s += r.wall_s;
    res.sim_s += r.sim_s;
    res.turn_on_bias_dph.push_back(bias_dph(r.rows, &sim_run::TelemetryRow::out_error_deg, t0, t1));
  }
  res.repeatability = bias_repeatability(res.turn_on_bias_dph);
}

// The scenario's temperature profile when it has one; otherwise a ramp of
// 20 degC over the hold.
void temperature_ramp(const ProcedureOptions& o, const ProcedureBase& base, DriftResult& res) {
  const double hold_s = o.short_run ? 120.0 : 300.0;
  constexpr int kSegments = 8;
  proc::Schedule sch(base.job.firmware.gyro.angular_gain);
  const double t0 = sch.t() + kSettleS;
  sch.hold(kSettleS + hold_s);
  sim_run::RunConfig job = proc::scheduled_job(base, sch);
  if (job.sim.temp_c.is_constant()) {
    const double c0 = job.sim.temp_c.value(0.0);
    job.sim.temp_c = sim::Profile::ramps({{0.0, c0}, {t0, c0}, {sch.t(), c0 + 20.0}});
  }
  const sim_run::RunResult r = proc::run(job, o, res.wall_s, res.sim_s);
  double model_sum = 0.0, model_n = 0.0;
  for (int s = 0; s < kSegments; ++s) {
    const double a = t0 + hold_s * s / kSegments, b = t0 + hold_s * (s + 1) / kSegments;
    double temp_sum = 0.0, n = 0.0;
    for (const sim_run::TelemetryRow& row : r.rows) {
      if (row.t_s < a || row.t_s > b) continue;
      temp_sum += row.temp_c;
      model_sum += row.drift_true_dph;
      model_n += 1.0;
      n += 1.0;
    }
    res.temperature_c.push_back(n > 0 ? temp_sum / n : 0.0);
    res.temperature_bias_dph.push_back(
        bias_dph(r.rows, &sim_run::TelemetryRow::out_error_deg, a, b));
    res.temperature_raw_bias_dph.push_back(
        bias_dph(r.rows, &sim_run::TelemetryRow::raw_error_deg, a, b));
  }
  res.temperature_model_dph = model_n > 0 ? model_sum / model_n : 0.0;
  res.temperature = bias_temperature_slope(res.temperature_c, res.temperature_bias_dph);
  res.temperature_raw = bias_temperature_slope(res.temperature_c, res.temperature_raw_bias_dph);
}

}  // namespace

DriftResult run_angle_dependent_bias(const ProcedureOptions& o) {
  const int angles = o.short_run ? 8 : 16;
  sim_run::RunConfig job = sim_run::make_run(o.scenario, {0.0, angles, false});
  DriftResult res;
  const sim_run::RunResult r = proc::run(job, o, res.wall_s, res.sim_s);
  res.adb_raw = r.fit_raw;
  res.adb_comp = r.fit_comp;
  res.adb_model = r.fit_model;
  res.parks = r.parks;
  // The pattern turns against the case at -K / 2: measured over the sweep.
  const sim_run::TelemetryRow& a = proc::row_at(r.rows, sim_run::kRingUpS);
  const sim_run::TelemetryRow& b = proc::row_at(r.rows, job.sweep_end_s);
  res.theta_at_sweep_end_deg = b.theta_deg;
  res.pattern_per_case = (b.theta_deg - a.theta_deg) / (b.true_angle_deg - a.true_angle_deg);
  return res;
}

DriftResult run_bias_repeatability(const ProcedureOptions& o) {
  DriftResult res;
  turn_ons(o, procedure_base(o), res);
  return res;
}

DriftResult run_drift(const ProcedureOptions& o) {
  DriftResult res = run_angle_dependent_bias(o);
  const ProcedureBase base = procedure_base(o);
  turn_ons(o, base, res);
  temperature_ramp(o, base, res);
  return res;
}

}  // namespace hrg::characterize
