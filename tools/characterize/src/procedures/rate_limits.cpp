// SPDX-License-Identifier: MIT
// IEEE 1431 12.10 on the simulated gyro: the rate threshold (dead zone) of
// the whole-angle pattern, raw and compensated, and the largest input rate
// the loops follow.
#include <algorithm>
#include <array>
#include <cmath>

#include "characterize/whole_angle_limits.hpp"
#include "common.hpp"

namespace hrg::characterize {

namespace {

using proc::kDeg;
using proc::kDph;
constexpr double kPi = std::numbers::pi;

// Zero crossing of the least-squares line y(x).
double zero_crossing(const std::vector<double>& x, const std::vector<double>& y) {
  const double s = sim_run::slope(x, y);
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i] / static_cast<double>(x.size());
    my += y[i] / static_cast<double>(x.size());
  }
  return s != 0.0 ? mx - my / s : 0.0;
}

// Turns the pattern from theta_now to the nearest angle where 4 theta equals
// 4 theta_target (mod 2 pi), through the case at `pattern_per_case`.
void turn_pattern_to(proc::Schedule& sch, double theta_now_rad, double theta_target_rad,
                     double pattern_per_case) {
  const double d_theta = std::remainder(theta_target_rad - theta_now_rad, kPi / 2.0);
  const double case_rad = d_theta / pattern_per_case;
  const double rate = 10.0 * kDeg;
  if (std::fabs(case_rad) < 1e-4) return;
  sch.table.turn(case_rad, rate, std::min(0.5, std::fabs(case_rad) / rate / 2.0));
}

// Input steps around the threshold at the least favourable angle: the raw
// output rate is Omega - D(theta) / K there and crosses zero at the threshold.
void rate_threshold(const ProcedureOptions& o, const ProcedureBase& base, const DriftResult& adb,
                    LimitsResult& res) {
  const double k = base.job.firmware.gyro.angular_gain;
  // b0 + a sin 4theta + c cos 4theta is lowest at 4 theta = atan2(a, c) + pi.
  const sim_run::BiasFit& f = adb.adb_raw;
  const double theta_min = (std::atan2(f.a_sin4, f.b_cos4) + kPi) / 4.0;
  const double scale_dph = std::max(f.amplitude() - f.b0, 1e-3);
  proc::Schedule sch(k);
  turn_pattern_to(sch, adb.theta_at_sweep_end_deg * kDeg, theta_min, adb.pattern_per_case);
  const double hold_s = o.short_run ? 10.0 : 20.0;
  struct Hold {
    double t0, t1;
  };
  std::vector<Hold> holds;
  for (const double frac : {0.6, 0.85, 1.15, 1.4}) {
    sch.set_rate(frac * scale_dph * kDph - base.earth_rad_s, 0.5);
    sch.hold(2.0);
    holds.push_back({sch.t(), sch.t() + hold_s});
    sch.hold(hold_s);
  }
  const sim_run::RunResult r = proc::run(proc::scheduled_job(base, sch), o, res.wall_s, res.sim_s);
  std::vector<double> in, raw, comp;
  double theta_sum = 0, d_true = 0, d_model = 0, n = 0;
  for (const Hold& h : holds) {
    ThresholdStep st;
    st.input_dph =
        proc::rate_of(r.rows, &sim_run::TelemetryRow::true_angle_deg, h.t0, h.t1) * 3600.0;
    st.raw_dph = proc::rate_of(r.rows, &sim_run::TelemetryRow::raw_angle_deg, h.t0, h.t1) * 3600.0;
    st.comp_dph = proc::rate_of(r.rows, &sim_run::TelemetryRow::out_angle_deg, h.t0, h.t1) * 3600.0;
    res.threshold_steps.push_back(st);
    in.push_back(st.input_dph);
    raw.push_back(st.raw_dph);
    comp.push_back(st.comp_dph);
    for (const sim_run::TelemetryRow& row : r.rows) {
      if (row.t_s < h.t0 || row.t_s > h.t1) continue;
      theta_sum += row.theta_deg;
      d_true += row.drift_true_dph;
      d_model += row.drift_model_dph;
      n += 1.0;
    }
  }
  res.measured_raw_dph = zero_crossing(in, raw);
  res.measured_comp_dph = zero_crossing(in, comp);
  res.theta_hold_deg = theta_sum / n;
  res.predicted_raw_dph = d_true / n;
  res.predicted_comp_dph = (d_true - d_model) / n;
  const sim::ResonatorParams& p = base.job.sim.resonator;
  res.closed_form_dph = rate_threshold_rad_s(damping_rate_per_s(p.f_hz, p.q), p.dmu, k) / kDph;
}

// Ascending rate steps, each held for whole 4 theta cycles (at least 1 s);
// followed: the output stays valid and within 1000 ppm of the input.
void input_rate_limit(const ProcedureOptions& o, const ProcedureBase& base, LimitsResult& res) {
  constexpr double kAccelDps2 = 1000.0;
  constexpr double kFollowPpm = 1000.0;
  const std::vector<double> rates_dps = o.short_run
                                            ? std::vector<double>{300.0, 1000.0, 3000.0}
                                            : std::vector<double>{300.0, 1000.0, 3000.0, 10000.0};
  const double k = base.job.firmware.gyro.angular_gain;
  const double cycle_case_deg = 180.0 / k;
  proc::Schedule sch(k);
  std::vector<std::array<double, 2>> records;
  double now_dps = 0.0;
  for (const double r : rates_dps) {
    sch.set_rate(r * kDeg, (r - now_dps) / kAccelDps2);
    now_dps = r;
    sch.hold(1.0);
    const double cycles = std::ceil(r * 1.0 / cycle_case_deg);
    records.push_back({sch.t(), sch.t() + cycles * cycle_case_deg / r});
    sch.hold(cycles * cycle_case_deg / r);
  }
  sch.set_rate(0.0, now_dps / kAccelDps2);
  sch.hold(1.0);
  const sim_run::RunResult r = proc::run(proc::scheduled_job(base, sch), o, res.wall_s, res.sim_s);
  for (const auto& rec : records) {
    bool valid = true;
    for (const sim_run::TelemetryRow& row : r.rows)
      if (row.t_s >= rec[0] && row.t_s <= rec[1]) valid = valid && row.out_valid;
    const proc::MeanRates m =
        proc::mean_rates(r.rows, &sim_run::TelemetryRow::out_angle_deg, rec[0], rec[1]);
    const RateStep step{m.input, m.output, 0.0};
    const bool ok =
        valid && std::fabs(step.output_rad_s / step.input_rad_s - 1.0) * 1e6 < kFollowPpm;
    res.rate_limit_steps.push_back(step);
    res.followed.push_back(ok);
    if (!ok) {
      res.limit_reached = true;
      break;
    }
    res.largest_followed_dps = step.input_rad_s / kDeg;
  }
}

}  // namespace

LimitsResult run_limits(const ProcedureOptions& o, const DriftResult& adb) {
  const ProcedureBase base = procedure_base(o);
  LimitsResult res;
  rate_threshold(o, base, adb, res);
  input_rate_limit(o, base, res);
  return res;
}

}  // namespace hrg::characterize
