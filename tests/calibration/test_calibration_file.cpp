// SPDX-License-Identifier: MIT
// The calibration's TOML form: round trip, and every kind of bad file refused
// with the key and line named.
#include "firmware/calibration_file.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "support/cpputest.hpp"

using namespace hrg::fw;

namespace {

// The message of the error `text` raises, or "" when it loads.
std::string error_of(const std::string& text) {
  try {
    parse_calibration(text, "gyro.toml");
  } catch (const CalibrationFileError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_GROUP(CalibrationFile){};

TEST(CalibrationFile, KeysCarryTheirUnitAndAnglesAreDegreesAtThisEdge) {
  CHECK_EQUAL(std::string("pickoff_y_gain"), calibration_file_key(0));
  CHECK_EQUAL(std::string("pickoff_y_phase_deg"), calibration_file_key(1));
  CHECK_EQUAL(std::string("pickoff_y_misalignment_deg"), calibration_file_key(2));
  const CalibrationFile f = parse_calibration(
      "# a comment\ncalibration_format = 1\npickoff_y_phase_deg = 1.0 # inline\n"
      "pickoff_y_gain = 0.0101\npickoff_y_gain_sigma = 7e-5\nduffing_hz_per_v2 = 2e-3\n",
      "gyro.toml");
  DOUBLES_EQUAL(1.0 * kDegToRad, f.calibration.pickoff_y_phase_rad, 1e-18);
  DOUBLES_EQUAL(0.0101, f.calibration.pickoff_y_gain, 0.0);
  DOUBLES_EQUAL(7e-5, f.sigma[0], 0.0);
  CHECK_TRUE(std::isnan(f.sigma[1]));
  DOUBLES_EQUAL(0.0, f.calibration.pickoff_y_misalignment_rad, 0.0);  // left out: identity
}

TEST(CalibrationFile, TheGapsSigmasAreTheFilesAndZeroWhereNotGiven) {
  // The firmware weighs them with its online pump fit (Estimator::check_known_gap).
  const CalibrationFile f = parse_calibration(
      "calibration_format = 1\ngap_eps_p = -0.0159\ngap_eps_p_sigma = 0.0013\n"
      "gap_eps_q = 0.0197\npickoff_y_gain_sigma = 7e-5\n",
      "gyro.toml");
  const GapSigma s = gap_sigma(f);
  DOUBLES_EQUAL(0.0013, s.eps_p, 0.0);
  DOUBLES_EQUAL(0.0, s.eps_q, 0.0);
  const GapSigma none = gap_sigma(CalibrationFile{});
  DOUBLES_EQUAL(0.0, none.eps_p, 0.0);
  DOUBLES_EQUAL(0.0, none.eps_q, 0.0);
}

TEST(CalibrationFile, SavedFileLoadsBackToTheSameCalibrationAndItsCrc) {
  CalibrationFile f;
  f.calibration.pickoff_y_gain = 0.0101234567890123;
  f.calibration.pickoff_y_misalignment_rad = 0.5004 * kDegToRad;
  f.calibration.feedthrough_y_im_v_per_v = -4.33e-4;
  f.calibration.temperature_ref_c = 31.25;
  f.calibration.nonlinear_damping_per_v2 = 0.05;
  f.calibration.gap_eps_p = -0.0198765;
  f.calibration.gap_eps_q = 0.0101;
  f.sigma[2] = 0.002 * kDegToRad;
  const std::string path = "test_calibration_file_roundtrip.toml";
  save_calibration(path, f, {"header line"}, {"not correctable: something, because"});
  const CalibrationFile back = load_calibration(path);
  std::remove(path.c_str());
  for (std::size_t i = 0; i < kCalibrationFieldCount; ++i) {
    const double a = f.calibration.*kCalibrationFields[i].member;
    const double b = back.calibration.*kCalibrationFields[i].member;
    DOUBLES_EQUAL(a, b, std::fabs(a) * 4e-16);
  }
  DOUBLES_EQUAL(f.sigma[2], back.sigma[2], f.sigma[2] * 4e-16);
  CHECK_TRUE(std::isnan(back.sigma[0]));
  // The CRC comment names what the file loads as.
  const std::string text = format_calibration(f, {}, {});
  char crc[16];
  std::snprintf(crc, sizeof crc, "0x%08X", calibration_crc(back.calibration));
  CHECK_TRUE(contains(text, crc));
}

TEST(CalibrationFile, BadFilesAreRefusedNamingTheKeyAndLine) {
  const std::string head = "calibration_format = 1\n";
  // Unknown key (a unit the file does not use), line 2.
  std::string e = error_of(head + "pickoff_y_phase_rad = 0.01\n");
  CHECK_TRUE(contains(e, "gyro.toml:2: key 'pickoff_y_phase_rad': unknown key"));
  // Out of range, in the file's unit, with the range.
  e = error_of(head + "\n\npickoff_y_misalignment_deg = 12.0\n");
  CHECK_TRUE(
      contains(e, "gyro.toml:4: key 'pickoff_y_misalignment_deg': 12.0 is out of range [-10"));
  e = error_of(head + "pickoff_y_gain = 0.5\n");
  CHECK_TRUE(contains(e, "key 'pickoff_y_gain': 0.5 is out of range [-0.2, 0.2]"));
  e = error_of(head + "thermal_damping_per_c = nan\n");
  CHECK_TRUE(contains(e, "key 'thermal_damping_per_c'"));
  // Not a number.
  e = error_of(head + "duffing_hz_per_v2 = \"2e-3\"\n");
  CHECK_TRUE(contains(e, "gyro.toml:2: key 'duffing_hz_per_v2': must be a number"));
  // Tables are not part of the format.
  e = error_of(head + "[pickoff]\ny_gain = 0.01\n");
  CHECK_TRUE(contains(e, "key 'pickoff': unknown key"));
  // Sigma negative.
  e = error_of(head + "pickoff_y_gain_sigma = -1e-5\n");
  CHECK_TRUE(contains(e, "key 'pickoff_y_gain_sigma': must be a finite number >= 0"));
  // Format missing or unknown.
  e = error_of("pickoff_y_gain = 0.01\n");
  CHECK_TRUE(contains(e, "key 'calibration_format': is required"));
  e = error_of("calibration_format = 2\n");
  CHECK_TRUE(contains(e, "gyro.toml:1: key 'calibration_format': must be 1"));
  // TOML syntax error: line and column.
  e = error_of(head + "pickoff_y_gain = = 1\n");
  CHECK_TRUE(contains(e, "gyro.toml:2:"));
  // Duplicate keys are a TOML error too.
  e = error_of(head + "pickoff_y_gain = 0.01\npickoff_y_gain = 0.02\n");
  CHECK_TRUE(contains(e, "gyro.toml:3:"));
  // Missing file.
  try {
    load_calibration("/nonexistent/gyro.toml");
    FAIL("loaded a missing file");
  } catch (const CalibrationFileError& err) {
    CHECK_TRUE(contains(err.what(), "/nonexistent/gyro.toml: cannot open"));
  }
  CHECK_EQUAL(std::string(""), error_of(head));
}

// toml++ 3.3.0 misreads some non-ASCII code points and asserts on a malformed
// table header: both are refused as errors with the place named, in every
// build (the sanitizer build keeps assertions on elsewhere).
TEST(CalibrationFile, NonAsciiTextAndMalformedHeadersAreErrorsNotCrashes) {
  const std::string non_ascii = error_of("calibration_format = 1\n# 0.5 \xc2\xb0 phase\n");
  CHECK_TEXT(contains(non_ascii, "gyro.toml:2:7: non-ASCII byte"), non_ascii.c_str());
  const std::string header = error_of("calibration_format = 1\n[[[1]]]\n");
  CHECK_TEXT(contains(header, "gyro.toml:2:"), header.c_str());
}
