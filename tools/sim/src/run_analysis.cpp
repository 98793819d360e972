// SPDX-License-Identifier: MIT
// The main job's figures from its telemetry rows: errors against the truth,
// the parked-angle bias and its 4 theta fit, the Allan deviation; and the
// truth itself (the simulated resonator's parameters and drift).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "estimator/drift.hpp"
#include "sim_run/run.hpp"

namespace hrg::sim_run {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Output minus truth accumulated between consecutive rows with a valid
// output, the drift model's prediction for the raw error (it falls behind
// the truth at D/K: Omega K = -2 theta' + D) and the tracking figures.
void accumulate_errors(RunResult& r, const RunConfig& job) {
  double sum2 = 0;
  std::size_t n = 0;
  const double dt_h = 1.0 / job.telemetry_hz / 3600.0;
  double model_deg = 0, bound_deg = 0, raw_err = 0, out_err = 0;
  double control_sum = 0, withheld_sum = 0;
  std::size_t control_n = 0;
  const TelemetryRow* prev = nullptr;
  for (TelemetryRow& row : r.rows) {
    if (row.out_valid && prev != nullptr && prev->out_valid) {
      const double d_true = row.true_angle_deg - prev->true_angle_deg;
      raw_err += row.raw_angle_deg - prev->raw_angle_deg - d_true;
      out_err += row.out_angle_deg - prev->out_angle_deg - d_true;
    }
    row.raw_error_deg = raw_err;
    row.out_error_deg = out_err;
    prev = &row;
    if (!row.out_valid) continue;
    if (row.t_s >= r.t_operate_s) {
      control_sum += row.drift_control_dph;
      withheld_sum += row.drift_withheld_dph;
      ++control_n;
    }
    model_deg -= row.drift_true_dph * dt_h;
    bound_deg += std::fabs(row.drift_true_dph) * dt_h;
    if (row.t_s < r.t_operate_s) continue;
    sum2 += out_err * out_err;
    ++n;
    r.tracking_max_deg = std::max(r.tracking_max_deg, std::fabs(out_err));
  }
  r.tracking_rms_deg = n ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0;
  r.control_drift_mean_dph = control_n ? control_sum / static_cast<double>(control_n) : 0.0;
  r.control_drift_withheld_mean_dph =
      control_n ? withheld_sum / static_cast<double>(control_n) : 0.0;
  r.model_error_end_deg = model_deg;
  r.drift_bound_deg = bound_deg;
  r.raw_error_end_deg = raw_err;
  r.comp_error_end_deg = out_err;
}

// Parked bias: slope of the angle error over each park, in deg/h, and the
// b + A sin 4theta + B cos 4theta fits.
void bias_goal_time(RunResult& r, const RunConfig& job) {
  r.bias_goal_dph = job.bias_goal_dph;
  const GoalTime g = uncertainty_goal_time(r.convergence, job.bias_goal_dph / 3.0);
  r.t_bias_goal_s = g.t_s;
  r.t_bias_goal_extrapolated = g.extrapolated;
}

// The compensated fit is over the parks where the firmware stood behind its
// model (compensation valid on every row): before that the output is the raw
// angle plus an unproven model, and a slow-converging resonator would be
// reported as not compensated at all.
void parked_bias(RunResult& r, const RunConfig& job) {
  std::vector<double> th, braw, bcomp, bmodel, th_valid;
  for (const TelemetryRow& row : r.rows) {
    if (row.comp_valid) {
      r.t_model_valid_s = row.t_s;
      break;
    }
  }
  for (const ParkedInterval& p : job.parks) {
    std::vector<double> t, eraw, ecomp, eraw_held, ecomp_held;
    double model = 0, theta_sum = 0;
    bool valid = true;
    bool moved = false;  // the firmware moved the pattern on purpose in the park
    for (const TelemetryRow& row : r.rows) {
      if (row.t_s < p.t_begin_s || row.t_s > p.t_end_s) continue;
      moved = moved || row.pattern_cmd;
      if (!row.out_valid) continue;
      valid = valid && row.comp_valid;
      t.push_back(row.t_s);
      eraw.push_back(row.raw_angle_deg - row.true_angle_deg);
      ecomp.push_back(row.out_angle_deg - row.true_angle_deg);
      eraw_held.push_back(row.raw_error_deg);
      ecomp_held.push_back(row.out_error_deg);
      theta_sum += row.theta_deg * kDeg;
      model += row.drift_true_dph;
    }
    // A move holds the output (the input turned meanwhile is not seen): the
    // bias is the slope of the error accumulated over the valid rows only.
    if (moved) {
      eraw.swap(eraw_held);
      ecomp.swap(ecomp_held);
    }
    if (t.size() < 10) continue;
    ParkResult pr;
    pr.theta_rad = theta_sum / static_cast<double>(t.size());
    pr.bias_raw_dph = slope(t, eraw) * 3600.0;
    pr.bias_comp_dph = slope(t, ecomp) * 3600.0;
    // The raw output error grows at -D/K (Omega K = -2 theta' + D).
    pr.bias_model_dph = -model / static_cast<double>(t.size());
    pr.model_valid = valid;
    r.parks.push_back(pr);
    th.push_back(pr.theta_rad);
    braw.push_back(pr.bias_raw_dph);
    bmodel.push_back(pr.bias_model_dph);
    if (valid) {
      th_valid.push_back(pr.theta_rad);
      bcomp.push_back(pr.bias_comp_dph);
    }
  }
  r.parks_model_valid = th_valid.size();
  r.fit_raw = fit_bias_4theta(th, braw);
  r.fit_comp = fit_bias_4theta(th_valid, bcomp);
  r.fit_model = fit_bias_4theta(th, bmodel);
  bias_goal_time(r, job);
  if (!job.parks.empty() &&
      (r.parks_model_valid < r.parks.size() || r.t_bias_goal_s > job.parks.front().t_begin_s)) {
    // The same bias test started once the model is valid and its bias
    // uncertainty has reached the goal: the run shifted by the wait (or,
    // never valid here, at least twice as long).
    const double wait_s = r.t_model_valid_s >= 0.0 ? std::max(r.t_model_valid_s, r.t_bias_goal_s) -
                                                         job.parks.front().t_begin_s
                                                   : job.duration_s;
    if (wait_s > 0.0) r.bias_test_needs_s = std::ceil(job.duration_s + wait_s);
  }
}

// Allan deviation of the compensated output rate (truth removed) over the
// longest stretch with a valid output on a still table (no rate-table
// motion, no commanded pattern move).
void still_allan(RunResult& r, const RunConfig& job) {
  const double earth_dps = job.earth_rate_rad_s / kDeg;
  std::size_t best_begin = 0, best_len = 0, begin = 0;
  for (std::size_t i = 0; i <= r.rows.size(); ++i) {
    const bool still = i < r.rows.size() && r.rows[i].out_valid && !r.rows[i].pattern_cmd &&
                       r.rows[i].t_s >= r.t_operate_s &&
                       std::fabs(r.rows[i].rate_dps - earth_dps) < 1e-6;
    if (still) continue;
    if (i - begin > best_len) {
      best_len = i - begin;
      best_begin = begin;
    }
    begin = i + 1;
  }
  std::vector<double> angle;
  for (std::size_t i = best_begin; i < best_begin + best_len; ++i) {
    angle.push_back(r.rows[i].out_error_deg * kDeg);
  }
  r.allan_span_s = static_cast<double>(best_len) / job.telemetry_hz;
  r.allan = allan_deviation(angle, 1.0 / job.telemetry_hz);
}

}  // namespace

std::array<double, 5> true_parameters(const sim::ResonatorParams& p) {
  const double nu = p.nu_per_s();
  const double dw = p.half_split_rad_s();
  return {nu, nu * p.dmu * std::cos(4 * p.th_mu_rad), nu * p.dmu * std::sin(4 * p.th_mu_rad),
          dw * std::cos(4 * p.th_w_rad), dw * std::sin(4 * p.th_w_rad)};
}

double true_drift_rad_s(const sim::ResonatorParams& p, double theta_rad, double q) {
  // The estimator's drift (physics.md section 3, exact in q = a_B/a_A) with
  // the true parameters.
  const std::array<double, 5> t = true_parameters(p);
  return est::resonator_drift_rad_s(Eigen::Map<const est::ParamVector>(t.data()), theta_rad, q);
}

void analyse_run(RunResult& r, const RunConfig& job) {
  accumulate_errors(r, job);
  parked_bias(r, job);
  still_allan(r, job);
}

GoalTime uncertainty_goal_time(std::span<const ConvergencePoint> c, double target_dph) {
  GoalTime g;
  for (const ConvergencePoint& p : c) {
    if (p.bias_sigma_dph <= target_dph) {
      g.t_s = p.t_s;
      return g;
    }
  }
  const std::size_t n = c.size();
  if (n < 4 || !(target_dph > 0.0)) return g;
  // The information 1/sigma^2 grows in proportion to the windows taken: its
  // rate over the last half of the solves (the schedule now in force, not
  // the campaign's), carried on from the last solve.
  std::vector<double> t, info;
  for (std::size_t i = n / 2; i < n; ++i) {
    t.push_back(c[i].t_s);
    info.push_back(1.0 / (c[i].bias_sigma_dph * c[i].bias_sigma_dph));
  }
  const double rate_per_s = slope(t, info);
  if (!(rate_per_s > 0.0)) return g;
  g.t_s = t.back() + (1.0 / (target_dph * target_dph) - info.back()) / rate_per_s;
  g.extrapolated = true;
  return g;
}

}  // namespace hrg::sim_run
