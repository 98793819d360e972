// SPDX-License-Identifier: MIT
// `hrg audit --calibration` with the firmware's own estimates in the
// recording's header (pump_edge_*, damping_check_*, self_cal_*): read,
// refused when malformed, combined with the audit's by one rule.
#include "audit/firmware_estimates.hpp"

#include <array>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

#include "audit/calibration_writer.hpp"
#include "recording/recording.hpp"

#include "support/audit_finding.hpp"
#include "support/cpputest.hpp"

using hrg::audit::AuditResult;
using hrg::audit::CombinedBy;
using hrg::audit::Effect;
using hrg::audit::Finding;
using hrg::test::audit_finding;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A recording whose header carries the switch-off check's keys: residual
// (1e-5, -2e-5, 3e-5, 0) on top of (4e-4, 6.9e-4, 6.9e-4, -4e-4) in force.
hrg::recording::Recording with_pump_edge_keys() {
  hrg::recording::Recording rec({"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc"}, 5000.0, 0.554);
  const std::array<std::array<const char*, 2>, 12> keys{{
      {"pump_edge_edges", "34"},
      {"pump_edge_x_re_v_per_v", "1e-5"},
      {"pump_edge_x_im_v_per_v", "-2e-5"},
      {"pump_edge_y_re_v_per_v", "3e-5"},
      {"pump_edge_y_im_v_per_v", "0"},
      {"pump_edge_sigma_v_per_v", "2e-6"},
      {"pump_edge_scatter_v_per_v", "3e-6"},
      {"pump_edge_in_force_s", "1700"},
      {"pump_edge_in_force_x_re_v_per_v", "4e-4"},
      {"pump_edge_in_force_x_im_v_per_v", "6.9e-4"},
      {"pump_edge_in_force_y_re_v_per_v", "6.9e-4"},
      {"pump_edge_in_force_y_im_v_per_v", "-4e-4"},
  }};
  for (const auto& [k, v] : keys)
    rec.set_metadata(k, v);
  return rec;
}

// The audit's feedthrough finding that, turned by the pump's 45 deg, is
// `k` per volt of pump (x re, x im, y re, y im).
Finding feedthrough_finding(const std::array<double, 4>& k, double sigma) {
  Finding f;
  f.effect = Effect::drive_feedthrough;
  f.sigma = sigma;
  const std::complex<double> rot = std::polar(1.0, kPi / 4.0);
  const auto x = std::complex<double>(k[0], k[1]) * rot;
  const auto y = std::complex<double>(k[2], k[3]) * rot;
  f.feedthrough_re_im = {x.real(), x.imag(), y.real(), y.imag()};
  f.value = std::abs(x);
  return f;
}

bool has_comment(const hrg::audit::CalibrationFromAudit& c, const std::string& a,
                 const std::string& b) {
  for (const auto& line : c.comments) {
    if (line.find(a) != std::string::npos && line.find(b) != std::string::npos) return true;
  }
  return false;
}

}  // namespace

TEST_GROUP(FirmwareEstimates){};

TEST(FirmwareEstimates, TwoEstimatesAreWeightedByInverseVarianceWithinFiveSigma) {
  // GIVEN the audit 1.0 +- 2 and the firmware 2.0 +- 1 (0.45 sigma apart)
  const double a[1] = {1.0}, f[1] = {2.0};
  const auto c = hrg::audit::combine_estimates(a, 2.0, f, 1.0);
  // THEN (1/4 * 1 + 1 * 2) / (1/4 + 1) = 1.8, sigma 1 / sqrt(1.25)
  CHECK(c.by == CombinedBy::weighted);
  DOUBLES_EQUAL(1.8, c.value[0], 1e-15);
  DOUBLES_EQUAL(1.0 / std::sqrt(1.25), c.sigma, 1e-15);
  DOUBLES_EQUAL(1.0 / std::sqrt(5.0), c.disagreement_sigmas, 1e-15);
}

TEST(FirmwareEstimates, BeyondFiveSigmaTheMorePreciseOneIsTakenAlone) {
  // GIVEN two parts, the second 5.1 sigma apart (sqrt(3^2 + 4^2) = 5)
  const double a[2] = {0.0, 0.0}, f[2] = {1.0, 25.5};
  const auto c = hrg::audit::combine_estimates(a, 3.0, f, 4.0);
  CHECK(c.by == CombinedBy::audit_alone);
  DOUBLES_EQUAL(0.0, c.value[1], 0.0);
  DOUBLES_EQUAL(3.0, c.sigma, 0.0);
  DOUBLES_EQUAL(5.1, c.disagreement_sigmas, 1e-12);
  // the firmware's, when it is the more precise
  const auto d = hrg::audit::combine_estimates(a, 4.0, f, 3.0);
  CHECK(d.by == CombinedBy::firmware_alone);
  DOUBLES_EQUAL(25.5, d.value[1], 0.0);
  // AND 4.9 sigma is still averaged
  const double g[2] = {1.0, 24.5};
  CHECK(hrg::audit::combine_estimates(a, 3.0, g, 4.0).by == CombinedBy::weighted);
}

TEST(FirmwareEstimates, TheHeaderKeysAreReadAndTheResidualAddedToWhatWasInForce) {
  const auto e = hrg::audit::firmware_estimates(with_pump_edge_keys(), "rec.csv");
  CHECK_TRUE(e.feedthrough.has_value());
  CHECK_FALSE(e.thermal_damping.has_value());
  DOUBLES_EQUAL(4.1e-4, e.feedthrough->total_v_per_v[0], 1e-18);
  DOUBLES_EQUAL(6.7e-4, e.feedthrough->total_v_per_v[1], 1e-18);
  DOUBLES_EQUAL(7.2e-4, e.feedthrough->total_v_per_v[2], 1e-18);
  DOUBLES_EQUAL(-4e-4, e.feedthrough->total_v_per_v[3], 1e-18);
  LONGS_EQUAL(34, e.feedthrough->edges);
  DOUBLES_EQUAL(1700.0, e.feedthrough->in_force_s, 0.0);
  // The scatter, larger than the stated sigma, is the sigma used.
  DOUBLES_EQUAL(3e-6, e.feedthrough->sigma_v_per_v, 0.0);
  // AND no keys: no estimates
  const hrg::recording::Recording bare({"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc"}, 5000.0,
                                       0.554);
  const auto none = hrg::audit::firmware_estimates(bare, "rec.csv");
  CHECK_FALSE(none.feedthrough.has_value());
  CHECK_FALSE(none.thermal_damping.has_value());
}

TEST(FirmwareEstimates, AMalformedOrMissingKeyIsRefusedByName) {
  const std::array<std::array<const char*, 2>, 6> bad{{
      {"pump_edge_sigma_v_per_v", "abc"},
      {"pump_edge_sigma_v_per_v", "-1e-6"},
      {"pump_edge_edges", "2.5"},
      {"pump_edge_y_im_v_per_v", "nan"},
      {"pump_edge_in_force_s", ""},  // missing, the rest of its group there
      {"damping_check_thermal_damping_per_c", "0.004x"},
  }};
  for (const auto& [key, value] : bad) {
    auto rec = with_pump_edge_keys();
    rec.set_metadata(key, value);
    if (std::string(key).rfind("damping_check", 0) == 0) {
      rec.set_metadata("damping_check_thermal_damping_sigma_per_c", "1e-4");
    }
    try {
      (void)hrg::audit::firmware_estimates(rec, "rec.csv");
      FAIL("a malformed header key was accepted");
    } catch (const std::runtime_error& e) {
      CHECK_TRUE(std::string(e.what()).find(std::string("'") + key + "'") != std::string::npos);
    }
  }
}

TEST(FirmwareEstimates, TheCalibrationFileHoldsTheCombinedFeedthroughAndSaysHow) {
  // GIVEN the audit's feedthrough (4e-4, 7e-4, 7e-4, -4e-4) +- 5.3e-6 and
  // the firmware's (4.1e-4, 6.7e-4, 7.2e-4, -4e-4) +- 3e-6 (its scatter):
  // at most 3e-5 / hypot(5.3e-6, 3e-6) = 4.9 sigma apart
  AuditResult r;
  r.verdict = "explained";
  r.findings.push_back(feedthrough_finding({4e-4, 7e-4, 7e-4, -4e-4}, 5.3e-6));
  hrg::audit::CalibrationWriterOptions opt;
  const auto plain = hrg::audit::calibration_from_audit(r, "rec.csv", opt);
  opt.firmware = hrg::audit::firmware_estimates(with_pump_edge_keys(), "rec.csv");
  const auto c = hrg::audit::calibration_from_audit(r, "rec.csv", opt);
  // THEN every part is the inverse-variance mean
  const double wa = 1.0 / (5.3e-6 * 5.3e-6), wf = 1.0 / (3e-6 * 3e-6);
  const auto mean = [&](double a, double f) { return (wa * a + wf * f) / (wa + wf); };
  const auto& k = c.file.calibration;
  DOUBLES_EQUAL(mean(4e-4, 4.1e-4), k.feedthrough_x_re_v_per_v, 1e-15);
  DOUBLES_EQUAL(mean(7e-4, 6.7e-4), k.feedthrough_x_im_v_per_v, 1e-15);
  DOUBLES_EQUAL(mean(7e-4, 7.2e-4), k.feedthrough_y_re_v_per_v, 1e-15);
  DOUBLES_EQUAL(mean(-4e-4, -4e-4), k.feedthrough_y_im_v_per_v, 1e-15);
  DOUBLES_EQUAL(1.0 / std::sqrt(wa + wf), c.file.sigma[3], 1e-18);
  CHECK_TRUE(has_comment(c, "weighted by inverse variance", "the firmware's"));
  // AND without the keys the file is the audit's, as before
  DOUBLES_EQUAL(4e-4, plain.file.calibration.feedthrough_x_re_v_per_v, 1e-15);
  DOUBLES_EQUAL(5.3e-6, plain.file.sigma[3], 0.0);
  CHECK_FALSE(has_comment(plain, "switch-off", ""));
  CHECK_FALSE(has_comment(plain, "weighted", ""));
  // AND a firmware 10 sigma off while more precise: taken alone, said why
  auto off = with_pump_edge_keys();
  off.set_metadata("pump_edge_x_im_v_per_v", "-9e-5");
  opt.firmware = hrg::audit::firmware_estimates(off, "rec.csv");
  const auto alone = hrg::audit::calibration_from_audit(r, "rec.csv", opt);
  DOUBLES_EQUAL(6e-4, alone.file.calibration.feedthrough_x_im_v_per_v, 1e-15);
  DOUBLES_EQUAL(3e-6, alone.file.sigma[4], 0.0);
  CHECK_TRUE(has_comment(alone, "the firmware's alone, the more precise", "more than 5"));
}

TEST(FirmwareEstimates, TheThermalDampingIsCombinedByTheSameRule) {
  // GIVEN the audit's 0.00370 +- 0.00033 /degC and the damping check's
  // 0.00391 +- 0.00015
  AuditResult r;
  r.verdict = "explained";
  r.temp_ref_c = 25.0;
  Finding f;
  f.effect = Effect::thermal_damping;
  f.value = 0.00370;
  f.sigma = 0.00033;
  r.findings.push_back(f);
  hrg::recording::Recording rec({"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc"}, 5000.0, 0.554);
  rec.set_metadata("damping_check_thermal_damping_per_c", "0.00391");
  rec.set_metadata("damping_check_thermal_damping_sigma_per_c", "0.00015");
  hrg::audit::CalibrationWriterOptions opt;
  opt.firmware = hrg::audit::firmware_estimates(rec, "rec.csv");
  const auto c = hrg::audit::calibration_from_audit(r, "rec.csv", opt);
  // THEN (0.0037 / 0.00033^2 + 0.00391 / 0.00015^2) / (1/0.00033^2 + 1/0.00015^2)
  const double wa = 1.0 / (0.00033 * 0.00033), wf = 1.0 / (0.00015 * 0.00015);
  DOUBLES_EQUAL((wa * 0.0037 + wf * 0.00391) / (wa + wf), c.file.calibration.thermal_damping_per_c,
                1e-15);
  DOUBLES_EQUAL(1.0 / std::sqrt(wa + wf), c.file.sigma[8], 1e-18);
  CHECK_TRUE(has_comment(c, "thermal_damping", "weighted by inverse variance"));
}

namespace {

constexpr double kDeg = kPi / 180.0;

// A recording whose header carries the pickoff self-calibration's whole map:
// the -1 deg misalignment row of the other resonator at seed 2 (365 s), the
// firmware's -1.00026 +- 0.00035 deg, its gain and phase within their noise.
hrg::recording::Recording with_self_cal_keys() {
  hrg::recording::Recording rec({"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc"}, 5000.0, 0.554);
  const auto put = [&](const char* k, double v) {
    rec.set_metadata(k, hrg::recording::format_number(v));
  };
  put("self_cal_gain", -1.36e-5);
  put("self_cal_gain_sigma", 1.56e-5);
  put("self_cal_misalignment_rad", -1.00026 * kDeg);
  put("self_cal_misalignment_sigma_rad", 0.00035 * kDeg);
  put("self_cal_phase_rad", -0.0012 * kDeg);
  put("self_cal_phase_sigma_rad", 0.00074 * kDeg);
  return rec;
}

}  // namespace

TEST(FirmwareEstimates, ThePickoffMapsKeysAreReadWithEachPartsSigma) {
  const auto e = hrg::audit::firmware_estimates(with_self_cal_keys(), "rec.csv");
  CHECK_TRUE(e.pickoff.has_value());
  CHECK_FALSE(e.feedthrough.has_value());
  DOUBLES_EQUAL(-1.36e-5, e.pickoff->gain.value, 1e-20);
  DOUBLES_EQUAL(1.56e-5, e.pickoff->gain.sigma, 1e-20);
  DOUBLES_EQUAL(-1.00026 * kDeg, e.pickoff->misalignment_rad.value, 1e-18);
  DOUBLES_EQUAL(0.00035 * kDeg, e.pickoff->misalignment_rad.sigma, 1e-20);
  DOUBLES_EQUAL(-0.0012 * kDeg, e.pickoff->phase_rad.value, 1e-20);
  DOUBLES_EQUAL(0.00074 * kDeg, e.pickoff->phase_rad.sigma, 1e-20);
  // AND a recording without them has none
  CHECK_FALSE(hrg::audit::firmware_estimates(with_pump_edge_keys(), "rec.csv").pickoff);
}

TEST(FirmwareEstimates, AMalformedOrMissingPickoffKeyIsRefusedByName) {
  const std::array<std::array<const char*, 2>, 6> bad{{
      {"self_cal_gain", "-1.5"},  // no inverse
      {"self_cal_gain_sigma", "0"},
      {"self_cal_misalignment_rad", "inf"},
      {"self_cal_misalignment_sigma_rad", ""},  // missing, the rest of its group there
      {"self_cal_phase_rad", "0.01x"},
      {"self_cal_phase_sigma_rad", "-1e-5"},
  }};
  for (const auto& [key, value] : bad) {
    auto rec = with_self_cal_keys();
    rec.set_metadata(key, value);
    try {
      (void)hrg::audit::firmware_estimates(rec, "rec.csv");
      FAIL("a malformed header key was accepted");
    } catch (const std::runtime_error& e) {
      CHECK_TRUE(std::string(e.what()).find(std::string("'") + key + "'") != std::string::npos);
    }
  }
}

TEST(FirmwareEstimates, AnAcceptedPickoffPartIsWeighedWithTheFirmwaresAndTheOthersAreNotApplied) {
  // GIVEN the audit's misalignment -0.99907 +- 0.00051 deg (its only
  // pickoff finding) and the firmware's map (-1.00026 +- 0.00035 deg)
  AuditResult r;
  r.verdict = "explained";
  r.findings.push_back(audit_finding(Effect::pickoff_misalignment, -0.99907, 0.00051));
  hrg::audit::CalibrationWriterOptions opt;
  const auto plain = hrg::audit::calibration_from_audit(r, "rec.csv", opt);
  opt.firmware = hrg::audit::firmware_estimates(with_self_cal_keys(), "rec.csv");
  const auto c = hrg::audit::calibration_from_audit(r, "rec.csv", opt);
  // THEN the file's misalignment is the inverse-variance mean, -0.99988
  // deg, between the two, its sigma 0.00029 deg below both
  const double wa = 1.0 / (0.00051 * 0.00051), wf = 1.0 / (0.00035 * 0.00035);
  const double mean_deg = (wa * -0.99907 + wf * -1.00026) / (wa + wf);
  const double b_deg = c.file.calibration.pickoff_y_misalignment_rad / kDeg;
  DOUBLES_EQUAL(mean_deg, b_deg, 1e-12);
  DOUBLES_EQUAL(-0.99988, b_deg, 2e-6);
  CHECK(b_deg < -0.99907 && b_deg > -1.00026);
  const double sigma_deg = c.file.sigma[2] / kDeg;  // pickoff_y_misalignment_rad
  DOUBLES_EQUAL(1.0 / std::sqrt(wa + wf), sigma_deg, 1e-12);
  CHECK(sigma_deg < 0.00035);
  CHECK_TRUE(has_comment(c, "pickoff_misalignment", "weighted by inverse variance"));
  // AND the gain and phase the audit did not accept stay 0, said, not applied
  DOUBLES_EQUAL(0.0, c.file.calibration.pickoff_y_gain, 0.0);
  DOUBLES_EQUAL(0.0, c.file.calibration.pickoff_y_phase_rad, 0.0);
  CHECK_TRUE(has_comment(c, "not applied", "pickoff_gain_mismatch -1.36e-05 +- 1.6e-05;"));
  CHECK_TRUE(has_comment(c, "not applied", "pickoff_phase_mismatch -0.0012 +- 0.00074 deg"));
  CHECK_FALSE(has_comment(c, "not applied", "pickoff_misalignment"));
  // AND without the keys the file is the audit's, as before
  DOUBLES_EQUAL(-0.99907, plain.file.calibration.pickoff_y_misalignment_rad / kDeg, 1e-12);
  DOUBLES_EQUAL(0.00051, plain.file.sigma[2] / kDeg, 1e-12);
  CHECK_FALSE(has_comment(plain, "self-calibration", ""));
}

TEST(FirmwareEstimates, EachPickoffPartIsCombinedWithItsOwnSigma) {
  // GIVEN the audit's gain 0.0101 +- 7e-5 and phase 1.0000 +- 0.004 deg,
  // the firmware's 0.01003 +- 2e-5 and 0.9990 +- 0.001 deg
  AuditResult r;
  r.verdict = "explained";
  r.findings.push_back(audit_finding(Effect::pickoff_gain_mismatch, 0.0101, 7e-5));
  r.findings.push_back(audit_finding(Effect::pickoff_phase_mismatch, 1.0, 0.004));
  auto rec = with_self_cal_keys();
  rec.set_metadata("self_cal_gain", "0.01003");
  rec.set_metadata("self_cal_gain_sigma", "2e-5");
  rec.set_metadata("self_cal_phase_rad", hrg::recording::format_number(0.999 * kDeg));
  rec.set_metadata("self_cal_phase_sigma_rad", hrg::recording::format_number(0.001 * kDeg));
  hrg::audit::CalibrationWriterOptions opt;
  opt.firmware = hrg::audit::firmware_estimates(rec, "rec.csv");
  const auto c = hrg::audit::calibration_from_audit(r, "rec.csv", opt);
  // THEN each part is its own inverse-variance mean
  const auto mean = [](double a, double sa, double f, double sf) {
    return (a / (sa * sa) + f / (sf * sf)) / (1.0 / (sa * sa) + 1.0 / (sf * sf));
  };
  DOUBLES_EQUAL(mean(0.0101, 7e-5, 0.01003, 2e-5), c.file.calibration.pickoff_y_gain, 1e-15);
  DOUBLES_EQUAL(mean(1.0, 0.004, 0.999, 0.001), c.file.calibration.pickoff_y_phase_rad / kDeg,
                1e-12);
  DOUBLES_EQUAL(1.0 / std::sqrt(1.0 / 49e-10 + 1.0 / 4e-10), c.file.sigma[0], 1e-18);
  // AND the misalignment the audit did not accept is said, not applied
  DOUBLES_EQUAL(0.0, c.file.calibration.pickoff_y_misalignment_rad, 0.0);
  CHECK_TRUE(has_comment(c, "not applied", "pickoff_misalignment -1.00026 +- 0.00035 deg"));
}
