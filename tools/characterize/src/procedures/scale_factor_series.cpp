// SPDX-License-Identifier: MIT
// IEEE 1431 12.9 scale-factor series on the simulated gyro: rate-table steps
// of both signs over 1.8 decades (5 ... 300 deg/s), each held for whole 4 theta
// cycles of the pattern (a case turn of pi / K per cycle), so that the 4 theta
// readout error ends where it began and leaves the step's mean rate alone.
#include <array>
#include <cmath>

#include "common.hpp"

namespace hrg::characterize {

namespace {

using proc::kDeg;

constexpr std::array<double, 5> kRatesDps{5.0, 15.0, 50.0, 150.0, 300.0};
constexpr double kAccelDps2 = 100.0;  // table acceleration between steps
constexpr double kSettleS = 1.0;      // loops settle at the new rate before the record

struct Interval {
  double t0_s, t1_s;
};

}  // namespace

ScaleFactorResult run_scale_factor(const ProcedureOptions& o) {
  const ProcedureBase base = procedure_base(o);
  const double k = base.job.firmware.gyro.angular_gain;
  const double cycle_case_rad = std::numbers::pi / k;  // one 4 theta cycle of the pattern
  const int cycles = o.short_run ? 1 : 2;
  proc::Schedule sch(k);
  std::vector<Interval> records;
  double rate_now_dps = 0.0;
  for (const double r : kRatesDps) {
    for (const double sign : {1.0, -1.0}) {
      const double rate_dps = sign * r;
      sch.set_rate(rate_dps * kDeg, std::fabs(rate_dps - rate_now_dps) / kAccelDps2 + 0.1);
      rate_now_dps = rate_dps;
      sch.hold(kSettleS);
      const double t0 = sch.t();
      sch.hold(cycles * cycle_case_rad / (r * kDeg));
      records.push_back({t0, sch.t()});
    }
  }
  sch.set_rate(0.0, std::fabs(rate_now_dps) / kAccelDps2 + 0.1);
  sch.hold(1.0);

  ScaleFactorResult res;
  const sim_run::RunResult run =
      proc::run(proc::scheduled_job(base, sch), o, res.wall_s, res.sim_s);
  for (std::size_t i = 0; i < records.size(); ++i) {
    const proc::MeanRates m = proc::mean_rates(run.rows, &sim_run::TelemetryRow::out_angle_deg,
                                               records[i].t0_s, records[i].t1_s);
    res.steps.push_back({m.input, m.output, 0.0});
    if (i >= 2) continue;  // the readout's 4 theta pattern from the slowest steps
    for (const sim_run::TelemetryRow& row : run.rows) {
      if (row.t_s < records[i].t0_s || row.t_s > records[i].t1_s || !row.out_valid) continue;
      res.true_theta_rad.push_back(row.true_theta_deg * kDeg);
      res.read_theta_rad.push_back(row.theta_deg * kDeg);
    }
  }
  res.series = analyze_scale_factor(res.steps);
  res.readout = analyze_angle_readout(res.true_theta_rad, res.read_theta_rad);
  return res;
}

}  // namespace hrg::characterize
