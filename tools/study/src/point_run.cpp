// SPDX-License-Identifier: MIT
// One seed of a grid point: the main job's schedule with the point's
// resonator, run through the main job's runner, sampled as it converges.
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "firmware/app/firmware.hpp"
#include "sim_run/report.hpp"
#include "sim_run/run.hpp"
#include "sim_run/scenario_run.hpp"
#include "study/point.hpp"

namespace hrg::study {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadSToDph = 180.0 / kPi * 3600.0;
// Noise in telemetry rows is not what the study measures: 10 rows per second
// keep a day's run in memory on every core and still resolve the parks.
constexpr double kTelemetryHz = 10.0;

// The main job's schedule (default_run) with the point's resonator and
// electrode gap; the default converters and ADC noise.
sim_run::RunConfig point_job(const Grid& grid, const PointSpec& spec, int seed_index) {
  sim_run::RunConfig j = sim_run::default_run(grid.duration_s, grid.bias_angles);
  sim::ResonatorParams& r = j.sim.resonator;
  r.q = spec.q;
  r.dmu = 0.5 * spec.dq_over_q;  // dQ/Q ~ 2 dmu
  r.split_hz = spec.split_hz;
  const double axis_rad = 4.0 * grid.gap_axis_deg * kPi / 180.0;
  j.sim.electrodes.eps_p = spec.gap * std::cos(axis_rad);
  j.sim.electrodes.eps_q = spec.gap * std::sin(axis_rad);
  j.sim.seed = grid.base_seed + static_cast<uint64_t>(seed_index);
  j.telemetry_hz = kTelemetryHz;
  j.description = "study point " + std::to_string(spec.index);
  sim_run::adopt_resonator(j, j.description);
  return j;
}

// The model in force against the truth, and its Cramer-Rao bound at unit
// per-sample noise (scaled once the run gives the noise), both as the 4 theta
// amplitude of the resonator drift on the input axis. With the quadrature
// nulled D(theta) = dnu_C sin 4theta - dnu_S cos 4theta (estimator/drift.hpp),
// so D(pi/8) = dnu_C and D(0) = -dnu_S.
class ConvergenceProbe {
 public:
  ConvergenceProbe(const sim_run::RunConfig& job, SeedResult& out)
      : truth_(sim_run::true_parameters(job.sim.resonator)),
        k_(job.firmware.gyro.angular_gain),
        out_(out) {}

  void operator()(const fw::app::Firmware& firmware, const sim::SimTarget& /*target*/) const {
    const fw::EstimatorPort& est = firmware.estimator();
    double e_c = truth_[1], e_s = truth_[2];
    if (firmware.gyro().status().compensation_applied) {
      e_c -= est.drift_rad_s(kPi / 8.0, 0.0, 0.0);
      e_s += est.drift_rad_s(0.0, 0.0, 0.0);
    }
    out_.model_adb_dph.push_back(std::hypot(e_c, e_s) / k_ * kRadSToDph);
    const est::ParamMatrix crb = est.estimator().cramer_rao_bound(1.0);
    const double var = crb(1, 1) + crb(2, 2);
    out_.crb_adb_dph.push_back(var > 0.0 ? std::sqrt(var) / k_ * kRadSToDph : -1.0);
  }

 private:
  std::array<double, 5> truth_;
  double k_;
  SeedResult& out_;
};

// A degenerate park set's fit trades its mean against its 4 theta terms: it
// gives no ADB (-1), and its bias is the parks' plain mean.
double adb_of(const sim_run::BiasFit& f) { return f.degenerate() ? -1.0 : f.amplitude(); }
double bias_of(const sim_run::BiasFit& f) { return f.degenerate() ? f.park_mean : f.b0; }

}  // namespace

void set_bias_test(const sim_run::BiasFit& raw, const sim_run::BiasFit& comp, SeedResult& s) {
  s.bias_fit = comp.ok && raw.ok;
  s.raw_parks_degenerate = raw.degenerate();
  s.comp_parks_degenerate = comp.degenerate();
  s.comp_parks_note = s.comp_parks_degenerate ? sim_run::degenerate_parks_note(comp) : "";
  s.raw_adb_dph = adb_of(raw);
  s.comp_adb_dph = adb_of(comp);
  s.raw_bias_dph = bias_of(raw);
  s.comp_bias_dph = bias_of(comp);
  s.meas_sigma_dph = std::hypot(comp.sigma_a, comp.sigma_b);
}

SeedResult run_seed(const Grid& grid, const PointSpec& spec, int seed_index) {
  const sim_run::RunConfig job = point_job(grid, spec, seed_index);
  SeedResult s;
  s.seed = job.sim.seed;
  sim_run::RunOptions opt;
  opt.observer = ConvergenceProbe(job, s);
  opt.observe_every_s = grid.sample_every_s;
  const sim_run::RunResult r = sim_run::run_simulation(job, opt);
  // The bound was taken at unit noise: scale by the run's per-sample noise.
  for (double& c : s.crb_adb_dph)
    if (c > 0.0) c *= r.noise_sigma_v;
  s.locked = r.reached_operate;
  s.t_converged_s = r.t_converged_s;
  s.comp_applied = r.compensation_applied;
  s.model_checks_failed = r.model_checks_failed;
  s.excitation_off = r.excitation_off_fraction;
  s.control_drift_mean_dph = r.control_drift_mean_dph;
  s.t_bias_start_s = job.parks.empty() ? -1.0 : job.parks.front().t_begin_s;
  set_bias_test(r.fit_raw, r.fit_comp, s);
  return s;
}

PointResult prepare_point(const Grid& grid, const PointSpec& spec) {
  PointResult p;
  p.spec = spec;
  try {
    const sim_run::RunConfig job = point_job(grid, spec, 0);
    const sim::ResonatorParams& r = job.sim.resonator;
    // The AGC holds a_A with the pump's growth rate k V0^2 / (8 w) equal to
    // the wave's decay rate, at most nu (1 + dmu) on the most damped axis.
    const double growth = r.nu_per_s() * (1.0 + r.dmu);
    p.pump_needed_v =
        std::sqrt(8.0 * r.omega_rad_s() * growth / job.sim.electrodes.pump_gain_per_s2_v2);
    p.pump_max_v = job.firmware.chain.pump_max_v;
  } catch (const std::invalid_argument& e) {
    p.setup_error = e.what();
  }
  return p;
}

}  // namespace hrg::study
