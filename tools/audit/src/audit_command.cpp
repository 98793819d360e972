// SPDX-License-Identifier: MIT
// `hrg audit RECORDING [--json OUT.json] [--plots DIR] [--calibration OUT.toml [--pump-phase-deg
// D]]`
#include "audit/audit_command.hpp"

#include <chrono>
#include <cmath>
#include <numbers>
#include <cstdlib>
#include <filesystem>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>
#include <string_view>

#include "audit/audit.hpp"
#include "audit/calibration_writer.hpp"
#include "audit/firmware_estimates.hpp"
#include "audit/plots.hpp"
#include "recording/recording.hpp"

namespace hrg::audit {

namespace {

void usage(std::FILE* f) {
  std::fprintf(f,
               "usage: hrg audit RECORDING [--json OUT.json] [--plots DIR]\n"
               "                 [--calibration OUT.toml [--pump-phase-deg D]]\n\n"
               "Fits the seed's averaged resonator model to an hrg-recording v1 file (.csv or\n"
               ".csv.gz), locates where it misfits, tests every effect of the catalogue as a\n"
               "nested extension and reports the verdict (consistent, explained, ambiguous,\n"
               "unexplained). Exit code 0 on success, 1 on bad input, 2 on bad usage.\n"
               "--calibration writes the accepted findings as the firmware's calibration file\n"
               "(with their 1-sigma uncertainties); --pump-phase-deg is the pump's phase\n"
               "against the wave in the firmware that recorded (default 45).\n");
  std::fputs(
      "The firmware's own estimates in the header (pump_edge_*, damping_check_*) are\n"
      "combined with the audit's where it found the same effect; a malformed key is\n"
      "refused.\n",
      f);
}

}  // namespace

int audit_main(std::span<char* const> args) {
  std::string path, json_out, plots_dir, calibration_out;
  CalibrationWriterOptions cal_opt;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    }
    if ((a == "--json" || a == "--plots" || a == "--calibration") && i + 1 < args.size()) {
      (a == "--json" ? json_out : a == "--plots" ? plots_dir : calibration_out) = args[++i];
    } else if (a == "--pump-phase-deg" && i + 1 < args.size()) {
      char* end = nullptr;
      const double deg = std::strtod(args[++i], &end);
      if (end == args[i] || *end != '\0' || !(std::fabs(deg) <= 360.0)) {
        std::fprintf(stderr, "hrg audit: --pump-phase-deg '%s' is not an angle in [-360, 360]\n",
                     args[i]);
        return 2;
      }
      cal_opt.pump_phase_rad = deg * std::numbers::pi / 180.0;
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
    // The firmware's own estimates in the header: refused before the audit
    // runs when a key is malformed.
    if (!calibration_out.empty()) cal_opt.firmware = firmware_estimates(rec, path);
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
    if (!calibration_out.empty()) {
      write_calibration_file(calibration_out, r, path, cal_opt);
      std::printf("calibration written to %s\n", calibration_out.c_str());
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
