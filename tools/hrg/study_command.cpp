// SPDX-License-Identifier: MIT
// `hrg study tolerance`: the firmware on the simulated target over a grid of
// resonators; the compensated ADB each reaches, when, and against the
// Cramer-Rao bound (tools/study/README.md).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "batch/batch.hpp"
#include "study/grid.hpp"
#include "study/output.hpp"
#include "study/point.hpp"

namespace hrg::cli {

namespace {

constexpr const char* kUsage =
    "usage: hrg study tolerance [--grid FILE.toml] [--jobs N] [--out DIR] [--no-plots]\n"
    "       hrg study tolerance --point K [--grid FILE.toml] [--jobs N]\n"
    "       hrg study tolerance --merge LINES [--grid FILE.toml] [--out DIR] [--no-plots]\n"
    "       hrg study tolerance --count [--grid FILE.toml]\n\n"
    "Runs the firmware on the simulated target over a grid of resonators (split,\n"
    "dQ/Q, ring-electrode gap harmonic, Q; default grid tools/study/default-grid.toml)\n"
    "for several seeds each, and reports per point the raw and compensated ADB and\n"
    "mean bias, the time the compensated model reaches 3 / 0.1 / 0.01 deg/h, the\n"
    "Cramer-Rao bound, and why a point misses twice the bound when it does.\n"
    "Writes DIR/study.json, and from it DIR/study.csv, DIR/adb_plane.png and\n"
    "DIR/adb_time.png (default DIR: study-out).\n"
    "  --jobs N    runs on N cores (default 0: all); the result does not depend on N\n"
    "  --point K   runs point K alone and prints its JSON line (a distributed\n"
    "              worker's task: tools/study/dask_study.py)\n"
    "  --merge F   writes the outputs from a file of point lines (one per point)\n"
    "  --count     prints the number of points\n"
    "Exit status: 0 done, 2 bad usage or input.\n";

std::string default_grid() {
  if (const char* env = std::getenv("HRG_STUDY_GRID")) return env;
  return HRG_STUDY_GRID;
}

std::string report_script() {
  if (const char* env = std::getenv("HRG_STUDY_REPORT_SCRIPT")) return env;
  return HRG_STUDY_REPORT_SCRIPT;
}

struct Args {
  std::string grid = default_grid();
  std::string out_dir = "study-out";
  std::string merge;
  unsigned jobs = batch::all_cores();
  long point = -1;
  bool count = false, plots = true;
};

bool parse_point(const char* v, long& point) {
  char* end = nullptr;
  point = std::strtol(v, &end, 10);
  return *v != '\0' && *end == '\0' && point >= 0;
}

// 0: parsed; 1: --help printed; 2: bad usage (reported).
int parse(std::span<char* const> args, Args& a) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view arg = args[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(kUsage, stdout);
      return 1;
    }
    if (arg == "--count") {
      a.count = true;
      continue;
    }
    if (arg == "--no-plots") {
      a.plots = false;
      continue;
    }
    const bool takes = arg == "--grid" || arg == "--out" || arg == "--jobs" || arg == "--point" ||
                       arg == "--merge";
    if (!takes) {
      std::fprintf(stderr, "hrg study tolerance: unknown option '%s'\n\n%s", args[i], kUsage);
      return 2;
    }
    if (i + 1 >= args.size()) {
      std::fprintf(stderr, "hrg study tolerance: %s needs a value\n", args[i]);
      return 2;
    }
    const char* v = args[++i];
    if (arg == "--grid") a.grid = v;
    if (arg == "--out") a.out_dir = v;
    if (arg == "--merge") a.merge = v;
    if (arg == "--jobs" && !batch::parse_jobs(v, a.jobs)) {
      std::fprintf(stderr, "hrg study tolerance: --jobs '%s' must be 0 (all cores) or more\n", v);
      return 2;
    }
    if (arg == "--point" && !parse_point(v, a.point)) {
      std::fprintf(stderr, "hrg study tolerance: --point '%s' must be an integer >= 0\n", v);
      return 2;
    }
  }
  if (a.point >= 0 && !a.merge.empty()) {
    std::fprintf(stderr, "hrg study tolerance: --point and --merge exclude each other\n");
    return 2;
  }
  return 0;
}

// study.json, then the CSV and the plots from it.
int write_outputs(const Args& a, const study::Grid& grid, const std::vector<std::string>& lines) {
  const std::filesystem::path dir(a.out_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "hrg study tolerance: cannot create '%s': %s\n", a.out_dir.c_str(),
                 ec.message().c_str());
    return 2;
  }
  study::write_study_json(dir, grid, lines);
  const std::string cmd = "/usr/bin/python3 '" + report_script() + "' '" +
                          (dir / "study.json").string() + "' '" + dir.string() + "'" +
                          (a.plots ? "" : " --no-plots");
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "hrg study tolerance: the report failed (%s); the data is in %s\n",
                 cmd.c_str(), (dir / "study.json").c_str());
    return 2;
  }
  return 0;
}

int run(const Args& a) {
  const study::Grid grid = study::load_grid(a.grid);
  if (a.count) {
    std::printf("%zu\n", grid.points());
    return 0;
  }
  if (a.point >= 0) {
    if (static_cast<std::size_t>(a.point) >= grid.points()) {
      std::fprintf(stderr, "hrg study tolerance: --point %ld is outside the grid (%zu points)\n",
                   a.point, grid.points());
      return 2;
    }
    const auto p = study::run_point(grid, static_cast<std::size_t>(a.point), a.jobs);
    std::printf("%s\n", study::point_json_line(p).c_str());
    return 0;
  }
  std::vector<std::string> lines;
  if (!a.merge.empty()) {
    lines = study::read_point_lines(a.merge, grid);
  } else {
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& p : study::run_grid(grid, a.jobs))
      lines.push_back(study::point_json_line(p));
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(stderr,
                 "hrg study tolerance: %zu points x %d seeds of %.0f s in %.1f s wall on %u jobs\n",
                 grid.points(), grid.seeds, grid.duration_s, wall_s, a.jobs);
  }
  return write_outputs(a, grid, lines);
}

}  // namespace

int study_main(std::span<char* const> args) {
  if (args.empty() || std::string_view(args[0]) != "tolerance") {
    const bool help = !args.empty() &&
                      (std::string_view(args[0]) == "--help" || std::string_view(args[0]) == "-h");
    std::fputs(kUsage, help ? stdout : stderr);
    return help ? 0 : 2;
  }
  Args a;
  if (const int rc = parse(args.subspan(1), a); rc != 0) return rc == 1 ? 0 : rc;
  try {
    return run(a);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg study tolerance: %s\n", e.what());
    return 2;
  }
}

}  // namespace hrg::cli
