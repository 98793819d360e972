// SPDX-License-Identifier: MIT
// Benchmark (prints figures): the main job's default scenario over one hour
// of simulated operation (issue 6's performance requirement): raw and
// compensated angle-dependent bias, excitation-off time, time to converge,
// identified parameters against the truth with their sigma and the
// Cramer-Rao bound. It takes one to two minutes of wall time. The accuracy
// goals are asserted (compensated ADB <= 0.05 deg/h, excitation off <= 10 %
// and within the window plan's budget, the run's own checks); the speed is
// only printed.
#include <algorithm>
#include <cstdio>

#include "sim_run/run.hpp"
#include "sim_run/report.hpp"

#include "support/cpputest.hpp"

namespace {
constexpr const char* kNames[5] = {"nu_per_s", "dnu_c_per_s", "dnu_s_per_s", "dw_c_rad_s",
                                   "dw_s_rad_s"};

// Issue 6's requirement for one hour of the default scenario.
constexpr double kAdbGoalDph = 0.05;

// The window plan's own excitation-off budget: the campaign's windows, then
// a model check window at least once per check period (and once at the
// first still base); continued identification adds windows only while the
// run's share stays within the operation duty. With 5 s check windows every
// 10 min that is 9.7 % of the hour (the campaign alone: 8.9 %).
double excitation_off_budget(const hrg::sim_run::RunConfig& job) {
  const auto& w = job.firmware.gyro.windows;
  const double frame_s = 1.0 / hrg::fw::kBaseRateHz;
  const double window_s = w.length_frames * frame_s;
  const double campaign_s = w.windows_per_bin * w.bins * window_s;
  const double checks =
      w.check_period_frames ? job.duration_s / (w.check_period_frames * frame_s) + 1.0 : 0.0;
  return std::max(w.operation_duty, (campaign_s + checks * window_s) / job.duration_s);
}

// Issue 19: the hour stays within 10 % of excitation off.
constexpr double kOffGoal = 0.10;

void run_benchmark() {
  const auto job = hrg::sim_run::default_run(3600.0, 16);
  auto r = hrg::sim_run::run_simulation(job, {});
  const bool passed = hrg::sim_run::judge(job, r);
  for (const auto& f : r.failures)
    std::printf("  run check failed: %s\n", f.c_str());
  std::printf("\none hour of the default scenario (%.0f simulated s, %s):\n", r.sim_s,
              passed ? "run checks pass" : "run checks FAIL");
  std::printf("  realtime factor %.1f x wall (%.1f s), %.1f x CPU; goal >= 200\n",
              r.realtime_factor, r.wall_s, r.realtime_factor_cpu);
  // The goal is held by CPU time: the wall-clock share moves with where the
  // loaded machine's preemptions land.
  std::printf(
      "  share in the simulated target (resonator + converters): %s; goal <= 40 %% by CPU "
      "time\n",
      hrg::sim_run::describe_share(r).c_str());
  const double off_budget = excitation_off_budget(job);
  std::printf("  excitation off %.2f %% (%u windows, %u accepted); window plan's budget %.1f %%\n",
              100.0 * r.excitation_off_fraction, r.windows, r.windows_accepted, 100.0 * off_budget);
  std::printf("  identification converged (window campaign done) at %.1f s\n", r.t_converged_s);
  std::printf("  angle-dependent bias (deg/h, input axis, %zu parked angles):\n", r.parks.size());
  std::printf("    raw          ADB %8.3f  mean %+7.3f +- %.4f\n", r.fit_raw.amplitude(),
              r.fit_raw.b0, r.fit_raw.sigma_b0);
  std::printf("    compensated  ADB %8.3f  mean %+7.3f +- %.4f   goal ADB <= 0.05\n",
              r.fit_comp.amplitude(), r.fit_comp.b0, r.fit_comp.sigma_b0);
  std::printf("    control-loop drift added (mean D_Phi/K) %+.3f deg/h\n",
              r.control_drift_mean_dph);
  std::printf("  identified parameters (per-sample amplitude noise %.2g V):\n", r.noise_sigma_v);
  std::printf("    %-12s %12s %10s %10s %12s %8s\n", "parameter", "estimate", "sigma", "CRB sigma",
              "truth", "err/sig");
  for (int i = 0; i < 5; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double sig = r.identification.sigma[i];
    std::printf("    %-12s %+12.4e %10.2e %10.2e %+12.4e %+8.2f\n", kNames[i],
                r.identification.p[i], sig, r.crb_sigma[k], r.truth[k],
                sig > 0 ? (r.identification.p[i] - r.truth[k]) / sig : 0.0);
  }
  // The default 365 s run beside it (its campaign alone takes ~12 %).
  const auto short_job = hrg::sim_run::default_run(0.0, 16);
  auto s = hrg::sim_run::run_simulation(short_job, {});
  std::printf(
      "  default %.0f s run: excitation off %.2f %%, raw ADB %.3f, compensated ADB %.3f "
      "deg/h (%zu of %zu parks with the model valid)\n",
      short_job.duration_s, 100.0 * s.excitation_off_fraction, s.fit_raw.amplitude(),
      s.fit_comp.amplitude(), s.parks_model_valid, s.parks.size());
  CHECK_TRUE(passed);
  CHECK_TRUE(r.campaign_done);
  CHECK_TRUE(r.t_converged_s > 0.0 && r.t_converged_s < job.sweep_end_s);
  CHECK_TRUE(r.parks.size() == 16);
  CHECK_TRUE(r.excitation_off_fraction <= off_budget);
  CHECK_TRUE(r.excitation_off_fraction <= kOffGoal);
  CHECK_TRUE(r.fit_comp.amplitude() <= kAdbGoalDph);
}
}  // namespace

TEST_GROUP(BenchSimHour){};

TEST(BenchSimHour, OneHourAngleDependentBiasAndIdentification) {
  // The simulated target is a process-wide instance that keeps its buffers.
  MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads();
  run_benchmark();
  MemoryLeakWarningPlugin::restoreNewDeleteOverloads();
}
