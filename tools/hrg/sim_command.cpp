// SPDX-License-Identifier: MIT
// `hrg sim`: the main job. Firmware + simulated target in lockstep at full
// rate, then a summary, report.json, telemetry.csv and plots.
#include "hrg/sim_command.hpp"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "firmware/calibration_file.hpp"
#include "sim_run/console.hpp"
#include "sim_run/run.hpp"
#include "sim_run/profile_report.hpp"
#include "sim_run/report.hpp"
#include "sim_run/scenario_run.hpp"

namespace hrg::cli {

namespace {

constexpr const char* kUsage =
    "usage: hrg sim [--scenario FILE] [--duration S] [--out DIR] [--can-log FILE]\n"
    "               [--bias-angles N] [--static-base] [--real-time] [--no-plots]\n"
    "               [--no-control-drift] [--calibration FILE] [--self-calibrate]\n"
    "               [--profile] [--quiet] [--telemetry-decimate N] [--telemetry-rotate-s S]\n\n"
    "Runs the firmware against the simulated resonator in lockstep at full rate\n"
    "(100 kHz ADC, 1 kHz base frame) and writes report.json, telemetry.csv,\n"
    "bias.csv, allan.csv and PNG plots into DIR (default: sim-out).\n\n"
    "Without --scenario: the seed's resonator (5 kHz, Q 5e6, dQ/Q 0.1, split\n"
    "5e-4 Hz), Earth rate at 55.75 deg N, ring-up from rest, a rate-table sweep\n"
    "an IEEE 1431 style bias test at 16 parked angles and a 100 s still hold:\n"
    "365 simulated s, about 10 s of wall time on a desktop core.\n"
    "--duration lengthens the parks (or shortens the run, dropping parks);\n"
    "from 1800 s on, 5 s windows while the table turns until 800 s come first.\n"
    "--static-base: no rate table; the firmware turns the pattern on purpose\n"
    "(pattern-angle command) to fill the 4 theta bins between windows.\n"
    "Every option combines with --scenario FILE or is refused with the reason\n"
    "(--static-base or --bias-angles with a scenario's own rate profile).\n"
    "--real-time paces the same executive by CLOCK_MONOTONIC (1 ms frames,\n"
    "SCHED_FIFO and mlockall when permitted) and counts deadline misses.\n"
    "--no-control-drift leaves the control-loop drift D_Phi out of the output\n"
    "(the resonator model is still applied), for comparison.\n"
    "--profile prints where the host time goes: per firmware task and per stage\n"
    "of the simulated target (drives, resonator, noise, ADC).\n"
    "--calibration FILE puts a calibration (hrg audit --calibration) in force:\n"
    "the pickoff-map inverse and the drive-feedthrough removal on the chain's\n"
    "demodulated quadratures.\n"
    "--self-calibrate lets the firmware identify the pickoff gain mismatch and\n"
    "misalignment from its own windows and apply them when the estimate is well\n"
    "conditioned and significant (the identification then starts again).\n"
    "--telemetry-decimate N writes every N-th telemetry row (100 Hz / N); the\n"
    "analysis still uses every row. --telemetry-rotate-s S starts a new file\n"
    "every S simulated seconds (telemetry-000.csv, ...): a 24 h run writes\n"
    "3.5 GB of telemetry at 100 Hz.\n"
    "Exit status: 0 passed, 1 the run failed its checks, 2 bad usage or input.\n";

bool parse_double(std::string_view s, double& out) {
  std::string tmp(s);
  char* end = nullptr;
  out = std::strtod(tmp.c_str(), &end);
  return end != tmp.c_str() && *end == '\0';
}

std::filesystem::path plots_script() {
  if (const char* env = std::getenv("HRG_PLOTS_SCRIPT")) return env;
  return HRG_PLOTS_SCRIPT;
}

struct SimOptions {
  std::string scenario, out_dir = "sim-out", can_log, calibration;
  double duration_s = 0.0;
  int bias_angles = 0;  // not given: the schedule's default
  bool plots = true, quiet = false, real_time = false, static_base = false, profile = false;
  bool control_drift = true;
  bool self_calibrate = false;
  sim_run::TelemetryFileOptions telemetry;
};

// Parses the command line into `o`. Returns -1 to go on, else the exit
// status (0 after --help, 2 on bad usage, with the message printed).
int parse_options(std::span<char* const> args, SimOptions& o) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    const auto value = [&](const char* what) -> const char* {
      if (i + 1 >= args.size()) {
        std::fprintf(stderr, "hrg sim: %s needs a value\n", what);
        return nullptr;
      }
      return args[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--calibration") {
      const char* v = value("--calibration");
      if (v == nullptr) return 2;
      o.calibration = v;
    } else if (a == "--scenario" || a == "--out" || a == "--can-log") {
      const char* v = value(args[i]);
      if (!v) return 2;
      (a == "--scenario" ? o.scenario : a == "--out" ? o.out_dir : o.can_log) = v;
    } else if (a == "--duration") {
      const char* v = value("--duration");
      if (!v) return 2;
      if (!parse_double(v, o.duration_s) || !(o.duration_s > 0)) {
        std::fprintf(stderr, "hrg sim: --duration '%s' is not a positive number of seconds\n", v);
        return 2;
      }
    } else if (a == "--bias-angles") {
      const char* v = value("--bias-angles");
      double n = 0;
      if (!v) return 2;
      if (!parse_double(v, n) || n < 4 || n > 360 || n != static_cast<int>(n)) {
        std::fprintf(stderr, "hrg sim: --bias-angles '%s' must be an integer in [4, 360]\n", v);
        return 2;
      }
      o.bias_angles = static_cast<int>(n);
    } else if (a == "--telemetry-decimate" || a == "--telemetry-rotate-s") {
      const char* v = value(args[i]);
      double x = 0;
      if (!v) return 2;
      const bool decimate = a == "--telemetry-decimate";
      if (!parse_double(v, x) || !(x > 0) || (decimate && (x != static_cast<int>(x) || x > 1e6))) {
        std::fprintf(stderr, "hrg sim: %s '%s' must be a positive %s\n", args[i - 1], v,
                     decimate ? "integer" : "number of seconds");
        return 2;
      }
      if (decimate) {
        o.telemetry.decimate = static_cast<std::size_t>(x);
      } else {
        o.telemetry.rotate_s = x;
      }
    } else if (a == "--static-base") {
      o.static_base = true;
    } else if (a == "--real-time") {
      o.real_time = true;
    } else if (a == "--self-calibrate") {
      o.self_calibrate = true;
    } else if (a == "--no-control-drift") {
      o.control_drift = false;
    } else if (a == "--no-plots") {
      o.plots = false;
    } else if (a == "--quiet") {
      o.quiet = true;
    } else if (a == "--profile") {
      o.profile = true;
    } else {
      std::fprintf(stderr, "hrg sim: unknown option '%s'\n\n%s", args[i], kUsage);
      return 2;
    }
  }
  return -1;
}

// The job the options ask for (throws on a bad scenario).
sim_run::RunConfig make_run(const SimOptions& o) {
  sim_run::RunConfig job =
      sim_run::make_run(o.scenario, {o.duration_s, o.bias_angles, o.static_base});
  job.firmware.gyro.compensate_control_drift = o.control_drift;
  job.firmware.online_pickoff_calibration = o.self_calibrate;
  if (!o.calibration.empty()) {
    const fw::CalibrationFile f = fw::load_calibration(o.calibration);
    job.firmware.calibration = f.calibration;
    job.firmware.calibration_gap_sigma = fw::gap_sigma(f);
  }
  return job;
}

// report.json, telemetry.csv, bias.csv, allan.csv into `dir` (throws).
void write_results(const std::filesystem::path& dir, const sim_run::RunConfig& job,
                   const sim_run::RunResult& r, const SimOptions& o) {
  std::ofstream(dir / "report.json") << sim_run::report_json(job, r);
  const auto files = sim_run::write_telemetry(dir / "telemetry.csv", job, r, o.telemetry);
  if (!o.quiet && (o.telemetry.decimate > 1 || o.telemetry.rotate_s > 0.0) && !files.empty()) {
    const std::string rotation =
        o.telemetry.rotate_s > 0.0 ? sim_run::fmt(" of %.0f s each", o.telemetry.rotate_s) : "";
    std::fprintf(stderr,
                 "hrg sim: telemetry: every %zu-th row (%.1f Hz) in %zu file(s)%s from %s\n",
                 o.telemetry.decimate, job.telemetry_hz / static_cast<double>(o.telemetry.decimate),
                 files.size(), rotation.c_str(), files.front().filename().string().c_str());
  }
  sim_run::write_bias_csv(dir / "bias.csv", r);
  sim_run::write_allan_csv(dir / "allan.csv", r);
}

void plot(const std::filesystem::path& dir, bool quiet) {
  const std::string cmd = "/usr/bin/python3 '" + plots_script().string() + "' '" + dir.string() +
                          "'" + (quiet ? " >/dev/null" : "");
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "hrg sim: plotting failed (%s); the results are in %s\n", cmd.c_str(),
                 dir.string().c_str());
  }
}

}  // namespace

int sim_main(std::span<char* const> args) {
  SimOptions o;
  if (const int status = parse_options(args, o); status >= 0) return status;
  sim_run::RunConfig job;
  try {
    job = make_run(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg sim: %s\n", e.what());
    return 2;
  }
  const std::filesystem::path dir(o.out_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "hrg sim: cannot create output directory '%s': %s\n", o.out_dir.c_str(),
                 ec.message().c_str());
    return 2;
  }
  if (!o.quiet) {
    std::fprintf(stderr, "hrg sim: %s; %.0f simulated s -> %s\n", job.description.c_str(),
                 job.duration_s, o.out_dir.c_str());
  }
  sim_run::RunResult r;
  try {
    sim_run::RunOptions opt;
    opt.progress = !o.quiet && sim_run::stderr_is_terminal();
    opt.can_log = o.can_log;
    opt.real_time = o.real_time;
    opt.profile = o.profile;
    r = sim_run::run_simulation(job, opt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg sim: %s\n", e.what());
    return 2;
  }
  const bool passed = sim_run::judge(job, r);
  try {
    write_results(dir, job, r, o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg sim: writing the results: %s\n", e.what());
    return 2;
  }
  if (!o.quiet) sim_run::print_summary(stdout, job, r);
  if (o.profile) std::fputs(sim_run::format_profile(r).c_str(), stdout);
  if (o.plots) plot(dir, o.quiet);
  if (!o.quiet) std::fprintf(stderr, "hrg sim: results in %s\n", o.out_dir.c_str());
  return passed ? 0 : 1;
}

}  // namespace hrg::cli
