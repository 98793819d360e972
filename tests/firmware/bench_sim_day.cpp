// SPDX-License-Identifier: MIT
// Benchmark (prints figures; a manual run, not a CTest): the default scenario
// over a long run (default 24 h) with continued identification in operation.
// Every hour it prints the excitation-off share, the windows, the memory
// (forgetting time) in force, the angle-dependent bias that the model in
// force leaves (its damping-anisotropy error against the truth at the
// resonator's present temperature, as input rate) and the Cramer-Rao
// prediction of it for the windows taken (sqrt of the bound's dnu_C, dnu_S
// variances over K). At the end, the parked-angle test's figures.
//
//   bench_sim_day [--hours H] [--thermal] [--period-h P] [--coefficient]
//                 [--adaptive-memory] [--rotate] [--forgetting-s S] [--duty D] [--window-s S]
//                 [--csv FILE]
//
// --csv: the hourly figures as CSV (default bench_sim_day.csv in the working
// directory; plot with tools/plots/day_plot.py). At the end the model ADB and
// its bound at 1, 3, 6, 12 and 24 h again, with the bound's fall against
// 1/sqrt(T) and the ADB's.
// --window-s: length of the operation windows (default the plan's, 30 s).
// --thermal: the thermal day. The resonator's frequency changes by 5 ppm/degC
// (thermal_frequency) and its damping by 0.4 %/degC (thermal_damping) under a
// +-2 degC sine of period --period-h (default one period over the run).
// --coefficient: the calibration carries both thermal coefficients (as the
// audit fits them), so the firmware refers its damping regressors and the
// drift to the temperature its sensor reads. --adaptive-memory: the
// estimator derives its memory from the parameters' seen motion
// (est::Estimator::Config::forgetting). --rotate: the operation windows walk
// the pattern to the least-covered 4 theta bin first
// (WindowConfig::rotate_in_operation); the run's held-output share and the
// windows per bin are printed. The model ADB is that of the
// correction in force: the identified anisotropy times the firmware's known
// damping factor now, against the truth at the resonator's temperature now.
// About 180 simulated s per CPU s: a 24 h run takes ~8 CPU minutes (run it
// under nice).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "firmware/app/firmware.hpp"
#include "sim_target/control.hpp"
#include "sim_run/run.hpp"
#include "sim_run/report.hpp"

namespace {
using namespace hrg;
constexpr double kRadSToDph = 180.0 / std::numbers::pi * 3600.0;

struct Options {
  double hours = 24.0;
  bool thermal = false;
  double period_h = 0.0;      // thermal swing's period (0: the run's length)
  bool coefficient = false;   // the calibration's thermal coefficients in force
  bool adaptive = false;      // memory derived from the parameters' motion
  bool rotate = false;        // operation windows walk the pattern to other angles
  double forgetting_s = 0.0;  // 0: derived by the estimator
  double duty = fw::app::kDefaultOperationDuty;
  double window_s = 0.0;  // operation windows' length (0: the plan's)
  std::string csv = "bench_sim_day.csv";
};

// One hourly observation.
struct Hour {
  double t_h = 0.0;
  double off_pct = 0.0;
  uint32_t windows = 0;
  double memory_s = 0.0;
  double temp_c = 0.0;
  double adb_dph = 0.0;
  double crb_dph = 0.0;
};

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (std::strcmp(argv[i], "--thermal") == 0) {
      o.thermal = true;
    } else if (std::strcmp(argv[i], "--coefficient") == 0) {
      o.coefficient = true;
    } else if (std::strcmp(argv[i], "--adaptive-memory") == 0) {
      o.adaptive = true;
    } else if (std::strcmp(argv[i], "--rotate") == 0) {
      o.rotate = true;
    } else if (std::strcmp(argv[i], "--period-h") == 0 && has_value) {
      o.period_h = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--hours") == 0 && has_value) {
      o.hours = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--forgetting-s") == 0 && has_value) {
      o.forgetting_s = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--window-s") == 0 && has_value) {
      o.window_s = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--duty") == 0 && has_value) {
      o.duty = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--csv") == 0 && has_value) {
      o.csv = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_sim_day [--hours H] [--thermal] [--period-h P] "
                   "[--coefficient] [--adaptive-memory] [--rotate] [--forgetting-s S] [--duty D] "
                   "[--window-s S] [--csv FILE]\n");
      return false;
    }
  }
  if (!(o.hours > 0.0 && o.duty > 0.0 && o.duty < 1.0 && o.period_h >= 0.0)) {
    std::fprintf(stderr,
                 "bench_sim_day: --hours must be > 0, --duty in (0, 1), --period-h >= 0 "
                 "(got %g, %g, %g)\n",
                 o.hours, o.duty, o.period_h);
    return false;
  }
  return true;
}

// The model's angle-dependent bias error and its Cramer-Rao prediction (deg/h).
Hour observe(const fw::app::Firmware& f, const sim::SimTarget& target,
             const sim_run::RunConfig& job, double noise_sigma_v) {
  const auto& est = f.estimator().estimator();
  const auto& sched = f.gyro().scheduler();
  const double k = job.firmware.gyro.angular_gain;
  const auto truth = sim_run::true_parameters(job.sim.resonator);
  const auto& fx = job.sim.effects.thermal_damping;
  const double scale =
      fx.enabled ? 1.0 + fx.rel_per_c * (target.true_state().temp_c - job.sim.resonator.temp_ref_c)
                 : 1.0;
  // The factor the firmware applies to its model now (1 without a thermal
  // coefficient; no nonlinear damping in this run, so the energy is moot).
  const double fw_scale = f.estimator().damping_scale(0.0);
  Hour h;
  h.t_h = f.gyro().status().chain.t_s / 3600.0;
  h.off_pct = 100.0 * sched.excitation_off_fraction();
  h.windows = sched.windows();
  h.memory_s = est.forgetting_time_s();
  h.temp_c = target.true_state().temp_c;
  if (est.has_model()) {
    h.adb_dph = std::hypot(fw_scale * est.model()(1) - scale * truth[1],
                           fw_scale * est.model()(2) - scale * truth[2]) /
                k * kRadSToDph;
    const est::ParamMatrix c = est.cramer_rao_bound(noise_sigma_v);
    h.crb_dph = fw_scale * std::sqrt(std::max(c(1, 1) + c(2, 2), 0.0)) / k * kRadSToDph;
  }
  return h;
}

// Thermal coefficients of the thermal day (the Gregory table's rows).
constexpr double kThermalFrequencyPpmPerC = 5.0;
constexpr double kThermalDampingPerC = 0.004;
constexpr double kSwingC = 2.0;

void set_thermal_day(const Options& o, sim_run::RunConfig& job) {
  auto& fx = job.sim.effects;
  fx.thermal_frequency.enabled = true;
  fx.thermal_frequency.ppm_per_c = kThermalFrequencyPpmPerC;
  fx.thermal_damping.enabled = true;
  fx.thermal_damping.rel_per_c = kThermalDampingPerC;
  const double period_s = o.period_h > 0.0 ? o.period_h * 3600.0 : job.duration_s;
  job.sim.temp_c = sim::Profile::sine(kSwingC, 1.0 / period_s, 0.0);
  job.sim.temp_c.add_offset(job.sim.resonator.temp_ref_c);
  if (!o.coefficient) return;
  job.firmware.calibration.thermal_frequency_ppm_per_c = kThermalFrequencyPpmPerC;
  job.firmware.calibration.thermal_damping_per_c = kThermalDampingPerC;
  job.firmware.calibration.temperature_ref_c = job.sim.resonator.temp_ref_c;
}

std::vector<uint32_t> windows_per_bin(const fw::WindowScheduler& s) {
  std::vector<uint32_t> n;
  for (uint32_t b = 0; b < s.config().bins; ++b)
    n.push_back(s.bin_count(b));
  return n;
}

// The windows per 4 theta bin at the last hour (campaign included) and the
// share of the run after the campaign with the output held by a pattern move.
void print_angle_diversity(const std::vector<uint32_t>& bins, const sim_run::RunResult& r) {
  std::printf("windows per 4 theta bin at the last hour:");
  for (uint32_t n : bins)
    std::printf(" %u", n);
  std::size_t rows = 0, held = 0;
  for (const auto& row : r.rows) {
    if (row.t_s < r.t_operate_s) continue;
    ++rows;
    held += row.pattern_cmd ? 1 : 0;
  }
  std::printf("\noutput held by pattern moves: %.2f %% of the rows after %.0f s\n",
              rows > 0 ? 100.0 * static_cast<double>(held) / static_cast<double>(rows) : 0.0,
              r.t_operate_s);
}

double ratio(double a, double b) { return b > 0.0 ? a / b : 0.0; }

void print_hour(const Hour& h) {
  std::printf(
      "  %6.1f h  off %5.2f %%  windows %4u  memory %8.0f s  T %6.2f C  model ADB %8.4f"
      "  CRB %8.4f  ratio %5.2f\n",
      h.t_h, h.off_pct, h.windows, h.memory_s, h.temp_c, h.adb_dph, h.crb_dph,
      ratio(h.adb_dph, h.crb_dph));
  std::fflush(stdout);
}

bool write_csv(const std::string& path, const std::vector<Hour>& hours) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "bench_sim_day: cannot write --csv %s\n", path.c_str());
    return false;
  }
  std::fprintf(f, "t_h,excitation_off_pct,windows,memory_s,temp_c,model_adb_dph,crb_adb_dph\n");
  for (const Hour& h : hours) {
    std::fprintf(f, "%.4f,%.4f,%u,%.1f,%.4f,%.6g,%.6g\n", h.t_h, h.off_pct, h.windows, h.memory_s,
                 h.temp_c, h.adb_dph, h.crb_dph);
  }
  return std::fclose(f) == 0;
}

// ADB and bound at 1, 3, 6, 12, 24 h (those the run reached); each against
// the first, as the factor 1/sqrt(T) predicts (sqrt(1 h / T)).
void print_convergence(const std::vector<Hour>& hours) {
  if (hours.empty() || !(hours.front().crb_dph > 0.0)) return;
  const Hour& first = hours.front();
  std::printf("convergence (against %.0f h; 1/sqrt(T) is the steady resonator's rate):\n",
              first.t_h);
  for (double mark : {1.0, 3.0, 6.0, 12.0, 24.0}) {
    for (const Hour& h : hours) {
      if (std::fabs(h.t_h - mark) > 0.05) continue;
      std::printf(
          "  %4.0f h  model ADB %8.4f  bound %8.4f deg/h  ratio %5.2f  bound/first %5.3f  "
          "ADB/first %5.3f  sqrt(first/T) %5.3f\n",
          h.t_h, h.adb_dph, h.crb_dph, ratio(h.adb_dph, h.crb_dph), ratio(h.crb_dph, first.crb_dph),
          ratio(h.adb_dph, first.adb_dph), std::sqrt(first.t_h / h.t_h));
    }
  }
}
}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) return 2;
  sim_run::RunConfig job = sim_run::default_run(o.hours * 3600.0, 16);
  job.telemetry_hz = 10.0;  // the analysis needs no more; a day at 100 Hz is 2 GB of rows
  job.firmware.gyro.windows.operation_duty = o.duty;
  if (o.window_s > 0.0) {
    job.firmware.gyro.windows.operation_length_frames =
        static_cast<uint32_t>(std::lround(o.window_s * fw::kBaseRateHz));
  }
  job.firmware.estimator.ls.forgetting_time_s = o.forgetting_s;
  job.firmware.estimator.forgetting.adaptive = o.adaptive;
  job.firmware.gyro.windows.rotate_in_operation = o.rotate;
  if (o.thermal) set_thermal_day(o, job);
  sim_run::derive_firmware_config(job);
  const double adc_sigma_v = job.sim.adc.noise_v_rms[0];
  const double noise_sigma_v =
      adc_sigma_v * std::sqrt(2.0 / static_cast<double>(job.firmware.chain.block_frames));
  std::printf("%.1f h of the default scenario", o.hours);
  if (o.thermal) {
    std::printf(
        " with thermal frequency %.0f ppm/degC and damping %.1f %%/degC under a +-%.0f degC "
        "sine of period %.1f h, thermal coefficients %s",
        kThermalFrequencyPpmPerC, 100.0 * kThermalDampingPerC, kSwingC,
        o.period_h > 0.0 ? o.period_h : o.hours, o.coefficient ? "in force" : "not known");
  }
  std::printf(", operation duty %.1f %%, memory %s:\n", 100.0 * o.duty,
              o.forgetting_s > 0 ? "set" : (o.adaptive ? "derived" : "none (no forgetting)"));
  sim_run::RunOptions opt;
  opt.observe_every_s = 3600.0;
  std::vector<Hour> hours;
  hours.reserve(static_cast<std::size_t>(o.hours) + 1);
  std::vector<uint32_t> bin_counts;
  opt.observer = [&](const fw::app::Firmware& f, const sim::SimTarget& t) {
    hours.push_back(observe(f, t, job, noise_sigma_v));
    print_hour(hours.back());
    bin_counts = windows_per_bin(f.gyro().scheduler());
  };
  sim_run::RunResult r = sim_run::run_simulation(job, opt);
  const bool passed = sim_run::judge(job, r);
  print_convergence(hours);
  for (const auto& p : r.parks) {
    std::printf("  park %7.2f deg  raw %+9.3f  compensated %+8.4f  truth %+9.3f deg/h%s\n",
                p.theta_rad * 180.0 / std::numbers::pi, p.bias_raw_dph, p.bias_comp_dph,
                p.bias_model_dph, p.model_valid ? "" : "  (model not valid)");
  }
  std::printf("control-loop drift added: mean %+.4f deg/h\n", r.control_drift_mean_dph);
  print_angle_diversity(bin_counts, r);
  if (r.fit_comp.degenerate())
    std::printf("parked-angle test: %s\n", sim_run::degenerate_parks_note(r.fit_comp).c_str());
  const bool written = write_csv(o.csv, hours);
  std::printf(
      "parked-angle test (%zu parks, %zu with the model valid): raw ADB %.3f, compensated "
      "ADB %.4f mean %+.4f deg/h; excitation off %.2f %%; %.0f simulated s per CPU s; "
      "run checks %s\n",
      r.parks.size(), r.parks_model_valid, r.fit_raw.amplitude(), r.fit_comp.amplitude(),
      r.fit_comp.b0, 100.0 * r.excitation_off_fraction, r.realtime_factor_cpu,
      passed ? "pass" : "FAIL");
  return passed && written ? 0 : 1;
}
