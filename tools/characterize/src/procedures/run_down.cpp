// SPDX-License-Identifier: MIT
// Angle storage and run-down (IEEE 1431 12.13, 12.14): after the ring-up and
// the sweep the board's fault input drops the firmware into safe mode (drives
// at zero, enable line low); the wave decays freely while the chain reads it.
// Measured: the decay rate, how the read pattern angle holds against the
// true one, and the time until the amplitude reaches the per-sample noise
// of the demodulated amplitude (extrapolated along the measured decay when
// the record ends first).
#include <cmath>

#include "characterize/whole_angle_limits.hpp"
#include "common.hpp"

namespace hrg::characterize {

using proc::kDeg;

RundownResult run_rundown(const ProcedureOptions& o) {
  const ProcedureBase base = procedure_base(o);
  RundownResult res;
  const double record_s = o.short_run ? 200.0 : 600.0;
  proc::Schedule sch(base.job.firmware.gyro.angular_gain);
  sch.hold(5.0);
  const double t_off = sch.t();
  sch.hold(record_s);
  sim_run::RunConfig job = proc::scheduled_job(base, sch);
  job.faults.push_back({t_off, sim_run::FaultEvent::Kind::fault_input, 0, true});
  const sim_run::RunResult r = proc::run(job, o, res.wall_s, res.sim_s);

  const double t0 = t_off + 1.0;  // the rows' averaging span free of the drive
  const sim_run::TelemetryRow& first = proc::row_at(r.rows, t0);
  const sim::ResonatorParams& p = base.job.sim.resonator;
  res.amplitude0_v = std::hypot(first.a_A_v, first.a_B_v);
  res.noise_floor_v = r.noise_sigma_v;
  std::vector<double> t, log_a;
  double offset_deg = first.theta_deg - first.true_theta_deg;
  for (const sim_run::TelemetryRow& row : r.rows) {
    if (row.t_s < t0) continue;
    const double a = std::hypot(row.a_A_v, row.a_B_v);
    const double tt = row.t_s - t0;
    res.t_s.push_back(tt);
    res.amplitude_v.push_back(a);
    res.model_v.push_back(free_decay_amplitude(res.amplitude0_v, tt, p.nu_per_s(), p.dmu,
                                               first.true_theta_deg * kDeg, p.th_mu_rad));
    t.push_back(tt);
    log_a.push_back(std::log(std::max(a, 1e-12)));
    const double err = row.theta_deg - row.true_theta_deg - offset_deg;
    res.readout_error_max_deg =
        std::max(res.readout_error_max_deg, std::fabs(std::remainder(err, 90.0)));
  }
  res.decay_rate_per_s = -sim_run::slope(t, log_a);
  const double model_end = std::log(res.model_v.back() / res.amplitude0_v);
  res.decay_rate_predicted_per_s = -model_end / res.t_s.back();
  res.rundown_s = std::log(res.amplitude0_v / res.noise_floor_v) / res.decay_rate_per_s;
  res.rundown_predicted_s = rundown_time_s(res.amplitude0_v, res.noise_floor_v, p.nu_per_s(), p.dmu,
                                           first.true_theta_deg * kDeg, p.th_mu_rad);
  return res;
}

}  // namespace hrg::characterize
