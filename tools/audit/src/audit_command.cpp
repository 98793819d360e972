// SPDX-License-Identifier: MIT
// `hrg audit RECORDING [--json OUT.json] [--plots DIR]`
#include "audit/audit_command.hpp"

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>
#include <string_view>

#include "audit/audit.hpp"
#include "audit/bench.hpp"
#include "campaign.hpp"
#include "audit/plots.hpp"
#include "recording/recording.hpp"

namespace hrg::audit {

namespace {

void usage(std::FILE* f) {
  std::fprintf(f,
               "usage: hrg audit RECORDING [--json OUT.json] [--plots DIR]\n\n"
               "Fits the seed's averaged resonator model to an hrg-recording v1 file (.csv or\n"
               ".csv.gz), locates where it misfits, tests every effect of the catalogue as a\n"
               "nested extension and reports the verdict (consistent, explained, ambiguous,\n"
               "unexplained). Exit code 0 on success, 1 on bad input, 2 on bad usage.\n");
}

}  // namespace

int audit_main(std::span<char* const> args) {
  std::string path, json_out, plots_dir;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    }
    if ((a == "--json" || a == "--plots") && i + 1 < args.size()) {
      (a == "--json" ? json_out : plots_dir) = args[++i];
    } else if (!a.empty() && a[0] != '-' && path.empty()) {
      path = a;
    } else {
      std::fprintf(stderr, "hrg audit: unexpected argument '%s'\n", args[i]);
      usage(stderr);
      return 2;
    }
  }
  if (path.empty()) {
    usage(stderr);
    return 2;
  }
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const recording::Recording rec = recording::read_recording(path);
    PlotData plot;
    const AuditResult r = run_audit(rec, AuditOptions{}, plots_dir.empty() ? nullptr : &plot);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fputs(to_text(r, path).c_str(), stdout);
    std::printf("(audit of %zu rows took %.2f s)\n", rec.rows(), secs);
    if (!json_out.empty()) {
      std::ofstream f(json_out);
      f << to_json(r);
      if (!f) throw std::runtime_error("cannot write " + json_out);
    }
    if (!plots_dir.empty()) {
      const std::string msg = write_plots(plot, r, plots_dir);
      std::printf("%s\n", msg.c_str());
    }
  } catch (const recording::RecordingError& e) {
    std::fprintf(stderr, "hrg audit: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg audit: %s: %s\n", path.c_str(), e.what());
    return 1;
  }
  return 0;
}

}  // namespace hrg::audit

namespace hrg::audit {

namespace {

void bench_usage(std::FILE* f) {
  std::fprintf(f,
               "usage: hrg audit-bench [--n DESIGNS] [--seed S] [--speed-hours H] [--verbose]\n\n"
               "Simulates DESIGNS random resonators and campaigns (ring-down and telemetry\n"
               "alternately) with sim_target; each gives one null recording and one recording\n"
               "per catalogue effect concealed at 0.3x-3x its detection threshold. Prints the\n"
               "confusion matrix, the hit rate above 2x, the false-finding rate on nulls and the\n"
               "confusable pairs, then times the audit of an H-hour 200 Hz recording (0: skip).\n\n"
               "       hrg audit-bench --emit OUT.csv[.gz] [--design ringdown|telemetry]\n"
               "                       [--duration S] [--seed S] [--effect ID VALUE] [--noise V]\n"
               "writes one simulated campaign, optionally with one catalogue effect.\n");
}

double speed_run(double hours, uint64_t seed) {
  const auto s = bench::random_scenario(bench::Design::telemetry, hours * 3600.0, seed);
  const auto rec = bench::simulate(s);
  const auto path = std::filesystem::temp_directory_path() /
                    ("hrg_audit_speed_" + std::to_string(seed) + ".csv.gz");
  recording::write_recording(path, rec);
  const auto t0 = std::chrono::steady_clock::now();
  const auto back = recording::read_recording(path);
  const auto r = run_audit(back);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::filesystem::remove(path);
  std::printf(
      "Speed: %.1f h recording, %zu rows at 200 Hz: read + audit %.2f s wall (goal <= 10 s), "
      "verdict %s\n",
      hours, back.rows(), secs, r.verdict.c_str());
  return secs;
}

}  // namespace

int audit_bench_main(std::span<char* const> args) {
  BenchOptions o;
  double hours = 1.0;
  std::string emit, design = "ringdown", effect;
  double duration_s = 480.0, value = 0.0, noise_v = -1.0;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    const bool has_value = i + 1 < args.size();
    if (a == "--help" || a == "-h") {
      bench_usage(stdout);
      return 0;
    } else if (a == "--n" && has_value) {
      o.designs = std::atoi(args[++i]);
    } else if (a == "--seed" && has_value) {
      o.seed = std::strtoull(args[++i], nullptr, 10);
    } else if (a == "--speed-hours" && has_value) {
      hours = std::atof(args[++i]);
    } else if (a == "--emit" && has_value) {
      emit = args[++i];
    } else if (a == "--design" && has_value) {
      design = args[++i];
    } else if (a == "--noise" && has_value) {
      noise_v = std::atof(args[++i]);
    } else if (a == "--duration" && has_value) {
      duration_s = std::atof(args[++i]);
    } else if (a == "--effect" && i + 2 < args.size()) {
      effect = args[++i];
      value = std::atof(args[++i]);
    } else if (a == "--verbose") {
      o.verbose = true;
    } else {
      std::fprintf(stderr, "hrg audit-bench: unexpected argument '%s'\n", args[i]);
      bench_usage(stderr);
      return 2;
    }
  }
  if (!emit.empty()) {
    // One simulated campaign written as a recording (for looking at by hand).
    auto sc = bench::random_scenario(
        design == "telemetry" ? bench::Design::telemetry : bench::Design::ringdown, duration_s,
        o.seed);
    if (!effect.empty() && !bench::conceal_by_id(sc, effect, value, o.seed)) {
      std::fprintf(stderr, "hrg audit-bench: unknown effect '%s'\n", effect.c_str());
      return 2;
    }
    if (noise_v >= 0.0) sc.noise_v = noise_v;
    recording::write_recording(emit, bench::simulate(sc));
    std::printf("wrote %s (f %.6f Hz, Q %.4g, dmu %.4g, split %.4g Hz, noise %.3g V)\n",
                emit.c_str(), sc.resonator.f_hz, sc.resonator.q, sc.resonator.dmu,
                sc.resonator.split_hz, sc.noise_v);
    return 0;
  }
  if (o.designs < 0) {
    std::fprintf(stderr, "hrg audit-bench: --n must not be negative\n");
    return 2;
  }
  if (o.designs > 0) {
    const BenchResult r = run_benchmark(o);
    std::printf("hrg audit benchmark: %d designs, seed %llu, %zu recordings\n\n", o.designs,
                static_cast<unsigned long long>(o.seed), r.cases.size());
    std::fputs(format_benchmark(r).c_str(), stdout);
  }
  if (hours > 0.0) speed_run(hours, o.seed);
  return 0;
}

}  // namespace hrg::audit
