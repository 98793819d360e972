// SPDX-License-Identifier: MIT
// `hrg audit --calibration`: the audit's accepted findings become the
// firmware's calibration file, with their uncertainties, and load back.
#include "audit/calibration_writer.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "audit/audit.hpp"
#include "audit/bench.hpp"
#include "../../tools/audit/src/campaign.hpp"
#include "firmware/calibration_file.hpp"
#include "recording/recording.hpp"

#include "support/audit_finding.hpp"
#include "support/cpputest.hpp"

namespace fs = std::filesystem;
using hrg::audit::AuditResult;
using hrg::audit::Effect;
using hrg::audit::Finding;
using hrg::test::audit_finding;

namespace {

fs::path shared_examples() {
  const char* src = std::getenv("HRG_SOURCE_DIR");
  return fs::path(src ? src : ".") / ".." / "shared" / "examples";
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_GROUP(AuditCalibration){};

TEST(AuditCalibration, GainMismatchExampleGivesAFileWhoseGainMatchesTheTruth) {
  const fs::path rec_path = shared_examples() / "ringdown-gain-mismatch.csv.gz";
  if (!fs::exists(rec_path)) {
    std::printf("\n%s not found: skipped\n", rec_path.c_str());
    return;
  }
  const AuditResult r = hrg::audit::run_audit(hrg::recording::read_recording(rec_path));
  const std::string out = "test_audit_calibration_gain.toml";
  hrg::audit::write_calibration_file(out, r, rec_path.string());
  const std::string text = read_text(out);
  const hrg::fw::CalibrationFile f = hrg::fw::load_calibration(out);
  std::remove(out.c_str());
  // Truth file: gain = 0.01783249666160052.
  const double truth = 0.01783249666160052;
  const double gain = f.calibration.pickoff_y_gain;
  const double sigma = f.sigma[0];
  std::printf("\n  example: gain %.6f +- %.1e, truth %.6f (%.2f sigma)\n", gain, sigma, truth,
              (gain - truth) / sigma);
  CHECK_TRUE(sigma > 0.0 && sigma < 0.01 * truth);
  CHECK_TRUE(std::fabs(gain - truth) <= 2.0 * sigma);
  // Nothing else was found, so nothing else is corrected.
  for (std::size_t i = 1; i < hrg::fw::kCalibrationFieldCount; ++i) {
    if (i == 9) continue;  // temperature_ref_c keeps the identity's value
    DOUBLES_EQUAL(0.0, f.calibration.*hrg::fw::kCalibrationFields[i].member, 0.0);
  }
  CHECK_TRUE(text.find("verdict: explained") != std::string::npos);
  CHECK_TRUE(text.find("pickoff_y_gain_sigma = ") != std::string::npos);
}

TEST(AuditCalibration, EveryFindingGoesToItsFieldInSiUnitsAndFeedthroughToThePumpsFrame) {
  AuditResult r;
  r.verdict = "explained";
  r.temp_ref_c = 31.5;
  r.findings.push_back(audit_finding(Effect::pickoff_phase_mismatch, 1.0, 0.004));  // deg
  r.findings.push_back(audit_finding(Effect::pickoff_misalignment, 0.5, 0.002));    // deg
  r.findings.push_back(audit_finding(Effect::thermal_frequency, 5.0, 0.01));        // ppm/degC
  r.findings.push_back(audit_finding(Effect::duffing_stiffness, 1.98e-3, 2e-5));    // Hz/V^2
  Finding ft = audit_finding(Effect::drive_feedthrough, 1e-3, 1e-5);
  // Against the wave: c_x = 1e-3 e^{i 75 deg}; the pump runs 45 deg ahead of
  // the wave, so per volt of pump envelope k_x = 1e-3 e^{i 30 deg}.
  const std::complex<double> cx = std::polar(1e-3, 75.0 * std::numbers::pi / 180.0);
  ft.feedthrough_re_im = {cx.real(), cx.imag(), 0.0, 5e-4};
  r.findings.push_back(ft);
  r.alternatives.push_back({Effect::thermal_damping, 0.003, 4.0, "some evidence"});
  const auto c = hrg::audit::calibration_from_audit(r, "rec.csv");
  const auto& k = c.file.calibration;
  constexpr double kDeg = std::numbers::pi / 180.0;
  DOUBLES_EQUAL(1.0 * kDeg, k.pickoff_y_phase_rad, 1e-15);
  DOUBLES_EQUAL(0.004 * kDeg, c.file.sigma[1], 1e-18);
  DOUBLES_EQUAL(0.5 * kDeg, k.pickoff_y_misalignment_rad, 1e-15);
  DOUBLES_EQUAL(5.0, k.thermal_frequency_ppm_per_c, 0.0);
  DOUBLES_EQUAL(31.5, k.temperature_ref_c, 0.0);
  DOUBLES_EQUAL(1.98e-3, k.duffing_hz_per_v2, 0.0);
  DOUBLES_EQUAL(1e-3 * std::cos(30.0 * kDeg), k.feedthrough_x_re_v_per_v, 1e-15);
  DOUBLES_EQUAL(1e-3 * std::sin(30.0 * kDeg), k.feedthrough_x_im_v_per_v, 1e-15);
  DOUBLES_EQUAL(5e-4 * std::sin(45.0 * kDeg), k.feedthrough_y_re_v_per_v, 1e-15);
  DOUBLES_EQUAL(5e-4 * std::cos(45.0 * kDeg), k.feedthrough_y_im_v_per_v, 1e-15);
  // The alternative is a comment with its reason, not a value.
  DOUBLES_EQUAL(0.0, k.thermal_damping_per_c, 0.0);
  bool listed = false;
  for (const auto& line : c.comments) {
    listed = listed || (line.find("not applied: thermal_damping") != std::string::npos &&
                        line.find("not an accepted finding") != std::string::npos);
  }
  CHECK_TRUE(listed);
}

TEST(AuditCalibration, AGapHarmonicFindingGoesToBothItsFieldsWithTheirSigmas) {
  AuditResult r;
  r.verdict = "explained";
  Finding g = audit_finding(Effect::gap_harmonics, std::hypot(0.0193, -0.0098), 0.0014);
  g.gap_eps_pq_sigma = {0.0193, -0.0098, 0.0014, 0.0008};
  r.findings.push_back(g);
  const auto c = hrg::audit::calibration_from_audit(r, "rec.csv");
  DOUBLES_EQUAL(0.0193, c.file.calibration.gap_eps_p, 0.0);
  DOUBLES_EQUAL(-0.0098, c.file.calibration.gap_eps_q, 0.0);
  DOUBLES_EQUAL(0.0014, c.file.sigma[13], 0.0);
  DOUBLES_EQUAL(0.0008, c.file.sigma[14], 0.0);
  // A gap harmonic outside the firmware's range (+-0.2) writes nothing.
  g.gap_eps_pq_sigma[1] = 0.3;
  r.findings = {g};
  CHECK_THROWS(hrg::fw::CalibrationFileError, hrg::audit::calibration_from_audit(r, "rec.csv"));
}

TEST(AuditCalibration, AFindingOutsideTheFirmwaresRangeWritesNothing) {
  AuditResult r;
  r.verdict = "explained";
  r.findings.push_back(audit_finding(Effect::pickoff_gain_mismatch, 0.3, 1e-4));  // range +-0.2
  const std::string out = "test_audit_calibration_refused.toml";
  std::remove(out.c_str());
  try {
    hrg::audit::write_calibration_file(out, r, "rec.csv");
    FAIL("an out-of-range finding was written");
  } catch (const hrg::fw::CalibrationFileError& e) {
    CHECK_TRUE(std::string(e.what()).find("'pickoff_y_gain'") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(out));
}

TEST_GROUP(AuditCalibrationSimulated){};

TEST(AuditCalibrationSimulated, FeedthroughIsWrittenPerVoltOfThePumpEnvelopeWithItsPhase) {
  // GIVEN a telemetry campaign (pump pi/4 ahead of the wave, as the chain)
  // whose pump couples into x at 1e-3 V/V, 30 deg and into y at 5e-4, -60 deg
  auto s = hrg::audit::bench::random_scenario(hrg::audit::bench::Design::telemetry, 600.0, 7);
  s.effects.drive_feedthrough = {true, 1e-3, 5e-4, 30.0, -60.0};
  const AuditResult r = hrg::audit::run_audit(hrg::audit::bench::simulate(s));
  const auto c = hrg::audit::calibration_from_audit(r, "campaign");
  // THEN the file holds k = c e^{i psi} per channel, the sim's own
  // coefficients (a feedthrough's sign is not defined: modulo 180 deg)
  const auto& k = c.file.calibration;
  const std::complex<double> kx(k.feedthrough_x_re_v_per_v, k.feedthrough_x_im_v_per_v);
  const std::complex<double> ky(k.feedthrough_y_re_v_per_v, k.feedthrough_y_im_v_per_v);
  const std::complex<double> tx = std::polar(1e-3, 30.0 * std::numbers::pi / 180.0);
  const std::complex<double> ty = std::polar(5e-4, -60.0 * std::numbers::pi / 180.0);
  const double sigma = c.file.sigma[3];
  const double ex = std::min(std::abs(kx - tx), std::abs(kx + tx));
  const double ey = std::min(std::abs(ky - ty), std::abs(ky + ty));
  std::printf(
      "\n  feedthrough: x %.3e at %.1f deg, y %.3e at %.1f deg (+- %.1e); truth 1e-3 at "
      "30, 5e-4 at -60\n",
      std::abs(kx), std::arg(kx) * 180.0 / std::numbers::pi, std::abs(ky),
      std::arg(ky) * 180.0 / std::numbers::pi, sigma);
  CHECK_TRUE(ex < std::max(3.0 * sigma, 0.05e-3));
  CHECK_TRUE(ey < std::max(3.0 * sigma, 0.05e-3));
}
