// SPDX-License-Identifier: MIT
// `hrg characterize`: the IEEE 1431 / 952 test procedures on the simulated
// gyro, written as a data sheet (datasheet.json, summary.txt, report.html).
// A command of its own rather than a mode of `hrg sim`: its product is the
// data sheet of several runs of the main job, not one run's report.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "batch/batch.hpp"
#include "characterize/procedures.hpp"

namespace hrg::cli {

namespace {

constexpr const char* kUsage =
    "usage: hrg characterize --test NAME|all [--test NAME ...] [--out DIR]\n"
    "                        [--scenario FILE] [--turn-ons N] [--short] [--no-render]\n"
    "                        [--jobs N] [--quiet]\n\n"
    "Runs the firmware on the simulated target (the runner of `hrg sim`) through\n"
    "the test procedures and writes the data sheet: DIR/datasheet.json, and from\n"
    "it DIR/summary.txt and a self-contained DIR/report.html (default DIR:\n"
    "characterize-out). Procedures (NAME):\n"
    "  scale_factor  IEEE 1431 12.9: +-5 ... +-300 deg/s, whole 4 theta cycles each\n"
    "  drift         IEEE 1431 12.11: parked-angle bias, N turn-ons (seeds), a\n"
    "                temperature ramp (the scenario's, else +20 degC)\n"
    "  limits        IEEE 1431 12.10: rate threshold raw and compensated at the\n"
    "                least favourable angle; rate steps up to 10000 deg/s\n"
    "  noise         IEEE 952: Allan deviation of a still record, ARW, bias\n"
    "                instability, rate random walk\n"
    "  rundown       IEEE 1431 12.13/12.14: excitation off, free decay, run-down\n"
    "--scenario takes a TOML scenario with a constant rate (the Earth rate).\n"
    "--short: shorter records (the CTest). --turn-ons N: bias repeatability runs\n"
    "(default 3). --jobs N: independent runs (the turn-ons) N at a time, default\n"
    "every core; the data sheet is the same for every N.\n"
    "Exit status: 0 done, 2 bad usage or input.\n";

std::filesystem::path datasheet_script() {
  if (const char* env = std::getenv("HRG_DATASHEET_SCRIPT")) return env;
  return HRG_DATASHEET_SCRIPT;
}

struct Args {
  std::vector<std::string> tests;
  std::string out_dir = "characterize-out";
  characterize::ProcedureOptions options;
  bool render = true, quiet = false;
};

// 0: parsed; 1: --help printed; 2: bad usage (reported).
int parse(std::span<char* const> args, Args& a) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view arg = args[i];
    const auto value = [&]() -> const char* {
      if (i + 1 < args.size()) return args[++i];
      std::fprintf(stderr, "hrg characterize: %s needs a value\n", args[i]);
      return nullptr;
    };
    const char* v = nullptr;
    if (arg == "--help" || arg == "-h") {
      std::fputs(kUsage, stdout);
      return 1;
    } else if (arg == "--jobs") {
      if ((v = value()) == nullptr) return 2;
      if (!batch::parse_jobs(v, a.options.jobs)) {
        std::fprintf(stderr,
                     "hrg characterize: --jobs '%s' must be a positive integer (0: every core)\n",
                     v);
        return 2;
      }
    } else if (arg == "--test" || arg == "--out" || arg == "--scenario" || arg == "--turn-ons") {
      if ((v = value()) == nullptr) return 2;
      if (arg == "--test") a.tests.emplace_back(v);
      if (arg == "--out") a.out_dir = v;
      if (arg == "--scenario") a.options.scenario = v;
      if (arg == "--turn-ons") {
        char* end = nullptr;
        const long n = std::strtol(v, &end, 10);
        if (*end != '\0' || n < 2 || n > 100) {
          std::fprintf(stderr, "hrg characterize: --turn-ons '%s' must be an integer in [2, 100]\n",
                       v);
          return 2;
        }
        a.options.turn_ons = static_cast<int>(n);
      }
    } else if (arg == "--short") {
      a.options.short_run = true;
    } else if (arg == "--no-render") {
      a.render = false;
    } else if (arg == "--quiet") {
      a.quiet = true;
    } else {
      std::fprintf(stderr, "hrg characterize: unknown option '%s'\n\n%s", args[i], kUsage);
      return 2;
    }
  }
  if (a.tests.empty()) {
    std::fprintf(stderr, "hrg characterize: name a --test (or --test all)\n\n%s", kUsage);
    return 2;
  }
  return 0;
}

}  // namespace

int characterize_main(std::span<char* const> args) {
  Args a;
  if (const int rc = parse(args, a); rc != 0) return rc == 1 ? 0 : rc;
  const std::filesystem::path dir(a.out_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "hrg characterize: cannot create output directory '%s': %s\n",
                 a.out_dir.c_str(), ec.message().c_str());
    return 2;
  }
  characterize::ProcedureReport rep;
  try {
    rep = characterize::run_procedures(a.tests, a.options);
    std::ofstream(dir / "datasheet.json") << rep.sheet_json;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg characterize: %s\n", e.what());
    return 2;
  }
  if (!a.quiet) {
    for (const std::string& l : rep.lines)
      std::printf("%s\n", l.c_str());
    std::printf("total: %.0f s simulated in %.1f s wall (%.0fx real time)\n", rep.sim_s, rep.wall_s,
                rep.wall_s > 0 ? rep.sim_s / rep.wall_s : 0.0);
  }
  if (a.render) {
    const std::string cmd = "/usr/bin/python3 '" + datasheet_script().string() + "' '" +
                            (dir / "datasheet.json").string() + "' '" + dir.string() + "'" +
                            (a.quiet ? " >/dev/null" : "");
    if (std::system(cmd.c_str()) != 0) {
      std::fprintf(stderr, "hrg characterize: rendering failed (%s); the data is in %s\n",
                   cmd.c_str(), (dir / "datasheet.json").c_str());
      return 2;
    }
  }
  if (!a.quiet) std::fprintf(stderr, "hrg characterize: data sheet in %s\n", a.out_dir.c_str());
  return 0;
}

}  // namespace hrg::cli
