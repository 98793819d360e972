// SPDX-License-Identifier: MIT
// IEEE 952 on the simulated gyro: a still record after the ring-up and the
// identification sweep; the Allan deviation of the compensated output rate
// (its angle error against the table: the Earth rate and any table motion
// removed) and the noise terms read on it.
#include "common.hpp"

namespace hrg::characterize {

NoiseResult run_noise(const ProcedureOptions& o) {
  const ProcedureBase base = procedure_base(o);
  const double record_s = o.short_run ? 200.0 : 600.0;
  proc::Schedule sch(base.job.firmware.gyro.angular_gain);
  sch.hold(5.0);
  const double t0 = sch.t();
  sch.hold(record_s);
  const sim_run::RunConfig job = proc::scheduled_job(base, sch);
  NoiseResult res;
  const sim_run::RunResult r = proc::run(job, o, res.wall_s, res.sim_s);
  std::vector<double> angle_rad;
  for (const sim_run::TelemetryRow& row : r.rows) {
    if (row.t_s < t0) continue;
    if (!row.out_valid) break;  // one contiguous stretch
    angle_rad.push_back(row.out_error_deg * proc::kDeg);
  }
  const double tau0_s = 1.0 / job.telemetry_hz;
  res.record_s = static_cast<double>(angle_rad.size()) * tau0_s;
  res.curve = allan_from_angle(angle_rad, tau0_s);
  res.terms = noise_terms(res.curve);
  res.readout_angle_noise_bound_rad =
      r.noise_sigma_v / (job.firmware.gyro.angular_gain * job.firmware.gyro.amplitude_set_v);
  return res;
}

}  // namespace hrg::characterize
