// SPDX-License-Identifier: MIT
#pragma once

// The calibration as a TOML file (host and Linux tools; the firmware core
// never parses text). One flat table, every key with its unit in its name:
//
//   calibration_format = 1
//   pickoff_y_gain = 0.0101
//   pickoff_y_gain_sigma = 7e-5        # optional: one standard deviation
//   pickoff_y_phase_deg = 1.0          # angles in degrees at this edge
//   ...
//
// Keys are the fields of kCalibrationFields, with `_rad` shown as `_deg`.
// A key left out keeps the identity's value (nothing corrected for it).
// Refused, naming the key and its line: an unknown key, a value that is not
// a number, a value outside the field's physical range, a negative sigma, a
// missing or unknown `calibration_format`. Comments are free.

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "firmware/calibration.hpp"

namespace hrg::fw {

class CalibrationFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CalibrationFile {
  Calibration calibration;
  // One standard deviation per field, in the field's SI unit; NaN = not given.
  std::array<double, kCalibrationFieldCount> sigma;
  CalibrationFile() { sigma.fill(std::numeric_limits<double>::quiet_NaN()); }
};

// The file's sigmas of gap_eps_p and gap_eps_q (0 where not given).
GapSigma gap_sigma(const CalibrationFile& file);

// The key of field i in the file (`_rad` -> `_deg`) and the factor from the
// file's unit to the field's SI unit.
std::string calibration_file_key(std::size_t field);
double calibration_file_to_si(std::size_t field);

// Parses TOML text; `source` names it in messages. Throws CalibrationFileError.
CalibrationFile parse_calibration(std::string_view toml_text, const std::string& source);
CalibrationFile load_calibration(const std::string& path);

// TOML text of `file`: `header` and `footer` lines are written as comments
// (without the leading '#'); every field is written (full precision), with
// its sigma where given, and the CRC-32 of the canonical form as a comment.
std::string format_calibration(const CalibrationFile& file, const std::vector<std::string>& header,
                               const std::vector<std::string>& footer);
// A C++ header defining hrg::fw::kBuiltInCalibration with every field as an
// exact hexadecimal floating literal (the bare-metal build's constant, see
// firmware/calibration_constant.hpp); `source` is named in its comment.
std::string format_calibration_header(const Calibration& c, const std::string& source);

// Writes format_calibration to `path`; throws CalibrationFileError on I/O failure.
void save_calibration(const std::string& path, const CalibrationFile& file,
                      const std::vector<std::string>& header,
                      const std::vector<std::string>& footer);

}  // namespace hrg::fw
