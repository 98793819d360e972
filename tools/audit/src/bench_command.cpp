// SPDX-License-Identifier: MIT
// `hrg audit-bench`: the audit's confusion matrix on simulated recordings.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <unistd.h>

#include "audit/audit.hpp"
#include "audit/audit_command.hpp"
#include "audit/bench.hpp"
#include "batch/batch.hpp"
#include "campaign.hpp"
#include "recording/recording.hpp"

namespace hrg::audit {

namespace {

void bench_usage(std::FILE* f) {
  std::fprintf(f,
               "usage: hrg audit-bench [--n DESIGNS] [--design K] [--seed S] [--jobs N]\n"
               "                       [--speed-hours H] [--verbose] [--no-singles]\n"
               "                       [--save-multi DIR]\n\n"
               "Simulates DESIGNS random resonators and campaigns in turn: a ring-down campaign\n"
               "and envelope-controlled telemetry (sim_target's averaged model), and the\n"
               "firmware's own telemetry (firmware + full-rate sim_target, as hrg sim runs it).\n"
               "Each gives one null recording and one recording per catalogue effect concealed\n"
               "at 0.3x-3x its detection threshold. Prints the confusion matrix, the hit rate\n"
               "above 2x, the false-finding rate on nulls and the confusable pairs, then times\n"
               "the audit of an H-hour 200 Hz recording (0: skip). --jobs N runs N designs at a\n"
               "time (default 0: all cores); the results and the output do not depend on N.\n"
               "--design K runs design K of the seed's sequence alone (0-based; --n, when given,\n"
               "must be above K), with the recordings, lines and counts it has in the full run.\n"
               "--no-singles skips the one-effect recordings (the others are those of the full\n"
               "run: null twin, 1/f null, pair, triple, outside); --save-multi DIR writes every "
               "1/f null, pair and\n"
               "triple recording to DIR (designK_coloured.csv.gz, designK_pair.csv.gz,\n"
               "designK_triple.csv.gz) for hrg audit.\n\n"
               "       hrg audit-bench --emit OUT.csv[.gz] [--design ringdown|telemetry|firmware]\n"
               "                       [--duration S] [--seed S] [--effect ID VALUE] [--noise V]\n"
               "                       [--flicker CORNER_HZ] [--outside SHAPE VALUE] [--pll]\n"
               "                       [--temp-follows-time]\n"
               "writes one simulated campaign, optionally with catalogue effects (--effect\n"
               "repeated; a firmware campaign lasts as long as its table turn; --duration is\n"
               "ignored),\n"
               "1/f noise, one effect outside the catalogue (gain_ratio_drift 1/h,\n"
               "phase_drift rad/h, offset_x V, gain_ratio_vs_temperature 1/degC) and a\n"
               "reference that follows the resonance (f_ref_hz per row). The temperature swings\n"
               "through two cycles with its line in time taken out, as in the benchmark;\n"
               "--temp-follows-time: one slow sine of 1.3 run lengths instead.\n");
}

bool parse_design(std::string_view name, bench::Design& d) {
  if (name == "ringdown") {
    d = bench::Design::ringdown;
  } else if (name == "telemetry") {
    d = bench::Design::telemetry;
  } else if (name == "firmware") {
    d = bench::Design::firmware;
  } else {
    return false;
  }
  return true;
}

double speed_run(double hours, uint64_t seed) {
  const auto s = bench::random_scenario(bench::Design::telemetry, hours * 3600.0, seed);
  const auto rec = bench::simulate(s);
  // The process id in the name: two benchmarks with the same seed at once
  // must not write and remove each other's file.
  const auto path =
      std::filesystem::temp_directory_path() /
      ("hrg_audit_speed_" + std::to_string(seed) + "_" + std::to_string(::getpid()) + ".csv.gz");
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

// The command line: the benchmark's options, or one recording to emit.
struct BenchArgs {
  BenchOptions o;
  double hours = 1.0;
  bool designs_given = false;  // --n on the command line
  std::string design_given;    // --design as written (a name with --emit, else a number)
  std::string emit, design = "ringdown", outside;
  std::vector<std::pair<std::string, double>> effects;  // --effect ID VALUE, repeatable
  double duration_s = 480.0, noise_v = -1.0, flicker_hz = 0.0, outside_value = 0.0;
  bool pll = false;
  bool temp_follows_time = false;
};

// Reads the option at args[i] (and its values); false with a message when
// it is unknown or its value is not one.
bool parse_option(std::span<char* const> args, std::size_t& i, BenchArgs& b) {
  const std::string_view a = args[i];
  const bool has_value = i + 1 < args.size();
  if (a == "--n" && has_value) {
    b.o.designs = std::atoi(args[++i]);
    b.designs_given = true;
  } else if (a == "--jobs" && has_value) {
    if (!batch::parse_jobs(args[++i], b.o.jobs)) {
      std::fprintf(stderr, "hrg audit-bench: --jobs '%s' is not a count (0: all cores)\n", args[i]);
      return false;
    }
  } else if (a == "--seed" && has_value) {
    b.o.seed = std::strtoull(args[++i], nullptr, 10);
  } else if (a == "--speed-hours" && has_value) {
    b.hours = std::atof(args[++i]);
  } else if (a == "--emit" && has_value) {
    b.emit = args[++i];
  } else if (a == "--design" && has_value) {
    b.design = b.design_given = args[++i];
  } else if (a == "--noise" && has_value) {
    b.noise_v = std::atof(args[++i]);
  } else if (a == "--duration" && has_value) {
    b.duration_s = std::atof(args[++i]);
  } else if (a == "--effect" && i + 2 < args.size()) {
    const std::string id = args[++i];
    b.effects.emplace_back(id, std::atof(args[++i]));
  } else if (a == "--flicker" && has_value) {
    b.flicker_hz = std::atof(args[++i]);
  } else if (a == "--outside" && i + 2 < args.size()) {
    b.outside = args[++i];
    b.outside_value = std::atof(args[++i]);
  } else if (a == "--pll") {
    b.pll = true;
  } else if (a == "--temp-follows-time") {
    b.temp_follows_time = true;
  } else if (a == "--verbose") {
    b.o.verbose = true;
  } else if (a == "--no-singles") {
    b.o.no_singles = true;
  } else if (a == "--save-multi" && has_value) {
    b.o.save_multi_dir = args[++i];
  } else {
    std::fprintf(stderr, "hrg audit-bench: unexpected argument '%s'\n", args[i]);
    bench_usage(stderr);
    return false;
  }
  return true;
}

// Without --emit, --design names one design of the benchmark by its number:
// it runs alone, and --n (implied as K + 1 when not given) must be above it.
bool select_design(BenchArgs& b) {
  if (b.design_given.empty()) return true;
  char* end = nullptr;
  const long k = std::strtol(b.design_given.c_str(), &end, 10);
  if (end == b.design_given.c_str() || *end != '\0' || k < 0 || k > 1000000) {
    std::fprintf(stderr,
                 "hrg audit-bench: --design '%s' is not a design number (0, 1, ...); names "
                 "(ringdown, telemetry, firmware) go with --emit\n",
                 b.design_given.c_str());
    return false;
  }
  b.o.only_design = static_cast<int>(k);
  if (!b.designs_given) b.o.designs = b.o.only_design + 1;
  if (b.o.designs <= b.o.only_design) {
    std::fprintf(stderr, "hrg audit-bench: --design %d needs --n above it (got --n %d)\n",
                 b.o.only_design, b.o.designs);
    return false;
  }
  return true;
}

// One simulated campaign written as a recording (for looking at by hand).
int emit_recording(const BenchArgs& b) {
  bench::Design design = bench::Design::ringdown;
  if (!parse_design(b.design, design)) {
    std::fprintf(stderr,
                 "hrg audit-bench: unknown --design '%s' (ringdown, telemetry or firmware)\n",
                 b.design.c_str());
    return 2;
  }
  auto sc = bench::random_scenario(design, b.duration_s, b.o.seed);
  for (const auto& [id, value] : b.effects) {
    if (!bench::conceal_by_id(sc, id, value, b.o.seed)) {
      std::fprintf(stderr, "hrg audit-bench: unknown effect '%s'\n", id.c_str());
      return 2;
    }
  }
  if (b.noise_v >= 0.0) sc.noise_v = b.noise_v;
  sc.flicker_corner_hz = b.flicker_hz;
  sc.pll_reference = b.pll;
  sc.temp_cycles = !b.temp_follows_time;
  if (!b.outside.empty() && !bench::outside_by_name(b.outside, sc.outside)) {
    std::fprintf(stderr, "hrg audit-bench: unknown --outside shape '%s'\n", b.outside.c_str());
    return 2;
  }
  sc.outside_value = b.outside_value;
  recording::write_recording(b.emit, bench::simulate(sc));
  std::printf("wrote %s (f %.6f Hz, Q %.4g, dmu %.4g, split %.4g Hz, noise %.3g V)\n",
              b.emit.c_str(), sc.resonator.f_hz, sc.resonator.q, sc.resonator.dmu,
              sc.resonator.split_hz, sc.noise_v);
  return 0;
}

}  // namespace

int audit_bench_main(std::span<char* const> args) {
  BenchArgs b;
  b.o.jobs = batch::all_cores();
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--help" || a == "-h") {
      bench_usage(stdout);
      return 0;
    }
    if (!parse_option(args, i, b)) return 2;
  }
  if (!b.emit.empty()) return emit_recording(b);
  if (!select_design(b)) return 2;
  if (b.o.designs < 0) {
    std::fprintf(stderr, "hrg audit-bench: --n must not be negative\n");
    return 2;
  }
  if (!b.o.save_multi_dir.empty()) std::filesystem::create_directories(b.o.save_multi_dir);
  if (b.o.designs > 0) {
    const BenchResult r = run_benchmark(b.o);
    if (b.o.only_design >= 0) {
      std::printf("hrg audit benchmark: design %d of %d, seed %llu, %zu recordings\n\n",
                  b.o.only_design, b.o.designs, static_cast<unsigned long long>(b.o.seed),
                  r.cases.size());
    } else {
      std::printf("hrg audit benchmark: %d designs, seed %llu, %zu recordings\n\n", b.o.designs,
                  static_cast<unsigned long long>(b.o.seed), r.cases.size());
    }
    std::fputs(format_benchmark(r).c_str(), stdout);
  }
  if (b.hours > 0.0) speed_run(b.hours, b.o.seed);
  return 0;
}

}  // namespace hrg::audit
