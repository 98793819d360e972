// SPDX-License-Identifier: MIT
// `hrg calibration-check FILE [--header OUT.hpp]`: validates a calibration file
// (TOML, firmware/calibration/io) and prints what it holds and its CRC-32 (the
// value the CAN block must carry); --header writes it as the bare-metal
// build's constant.
#include <cstdio>
#include <fstream>
#include <span>
#include <string>
#include <string_view>

#include "firmware/calibration_file.hpp"

namespace hrg::cli {

namespace {

void usage(std::FILE* f) {
  std::fprintf(f,
               "usage: hrg calibration-check FILE [--header OUT.hpp]\n\n"
               "Checks a calibration file (keys with units, physical ranges; unknown keys\n"
               "and out-of-range values are reported with the key and line), prints its\n"
               "values and CRC-32, and with --header writes it as a C++ header for\n"
               "cmake -DHRG_CALIBRATION_HEADER=OUT.hpp. Exit 1 on a bad file, 2 on bad usage.\n");
}

}  // namespace

int calibration_check_main(std::span<char* const> args) {
  std::string path;
  std::string header;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    }
    if (a == "--header" && i + 1 < args.size()) {
      header = args[++i];
    } else if (!a.empty() && a[0] != '-' && path.empty()) {
      path = a;
    } else {
      usage(stderr);
      return 2;
    }
  }
  if (path.empty()) {
    usage(stderr);
    return 2;
  }
  try {
    const fw::CalibrationFile f = fw::load_calibration(path);
    std::printf("%s: ok, CRC-32 0x%08X\n", path.c_str(), fw::calibration_crc(f.calibration));
    for (std::size_t i = 0; i < fw::kCalibrationFieldCount; ++i) {
      const double k = 1.0 / fw::calibration_file_to_si(i);
      std::printf("  %-32s %.9g\n", fw::calibration_file_key(i).c_str(),
                  f.calibration.*fw::kCalibrationFields[i].member * k);
    }
    if (!header.empty()) {
      std::ofstream out(header);
      out << fw::format_calibration_header(f.calibration, path);
      if (!out.flush()) throw fw::CalibrationFileError(header + ": cannot write");
      std::printf("header written to %s\n", header.c_str());
    }
  } catch (const fw::CalibrationFileError& e) {
    std::fprintf(stderr, "hrg calibration-check: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace hrg::cli
