// SPDX-License-Identifier: MIT
#include "audit/calibration_writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <span>
#include <string_view>

namespace hrg::audit {

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Index of a field of kCalibrationFields by its key.
std::size_t field(const char* key) {
  for (std::size_t i = 0; i < fw::kCalibrationFieldCount; ++i) {
    if (std::string(fw::kCalibrationFields[i].key) == key) return i;
  }
  throw std::logic_error(std::string("no calibration field ") + key);
}

std::string fmt(const char* f, double a, double b = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

// Sets a field from a catalogue value and its sigma (scale: catalogue -> SI),
// refusing a value outside the field's range.
void set(fw::CalibrationFile& out, const char* key, double value, double sigma, double scale) {
  const std::size_t i = field(key);
  const fw::CalibrationField& f = fw::kCalibrationFields[i];
  const double v = value * scale;
  if (!(v >= f.min && v <= f.max)) {
    throw fw::CalibrationFileError(std::string("audit finding for '") + key +
                                   "' = " + fmt("%.6g", v) + " is outside the firmware's range; " +
                                   "no calibration written");
  }
  out.calibration.*f.member = v;
  out.sigma[i] = std::fabs(sigma * scale);
}

// The audit's estimate and, when the firmware made its own, the two combined
// (combine_estimates), with the comment that says how.
CombinedEstimate with_firmware(std::span<const double> audit, double sigma, const double* firmware,
                               double firmware_sigma, const std::string& what,
                               const std::string& unit, std::vector<std::string>& comments) {
  CombinedEstimate c;
  std::copy(audit.begin(), audit.end(), c.value.begin());
  c.sigma = sigma;
  if (firmware == nullptr) return c;
  const std::span<const double> fw(firmware, audit.size());
  if (!(sigma > 0.0)) {
    comments.push_back("not combined: " + what +
                       ": the audit's estimate has no sigma; the "
                       "audit's value is written");
    return c;
  }
  c = combine_estimates(audit, sigma, fw, firmware_sigma);
  comments.push_back(describe_combination(what, audit, sigma, fw, firmware_sigma, c, unit));
  return c;
}

void set_feedthrough(fw::CalibrationFile& out, const Finding& f,
                     const CalibrationWriterOptions& opt, std::vector<std::string>& comments) {
  const std::complex<double> rot = std::polar(1.0, -opt.pump_phase_rad);
  const std::complex<double> cx =
      std::complex<double>(f.feedthrough_re_im[0], f.feedthrough_re_im[1]) * rot;
  const std::complex<double> cy =
      std::complex<double>(f.feedthrough_re_im[2], f.feedthrough_re_im[3]) * rot;
  comments.push_back(
      fmt("drive_feedthrough: per volt of the pump envelope, taken %.1f deg ahead "
          "of the wave (--pump-phase-deg); sigma is that of the larger |c|",
          opt.pump_phase_rad / kDegToRad));
  const std::array<double, 4> audit{cx.real(), cx.imag(), cy.real(), cy.imag()};
  const auto& edges = opt.firmware.feedthrough;
  if (edges) {
    comments.push_back(fmt("drive_feedthrough: the firmware's switch-off step check: %.0f edges",
                           static_cast<double>(edges->edges)) +
                       fmt(" through a correction in force for %.0f s, its residual added to "
                           "that correction's feedthrough",
                           edges->in_force_s) +
                       fmt("; sigma %.2g", edges->check_sigma_v_per_v) +
                       fmt(", from the edges' scatter %.2g V/V", edges->scatter_v_per_v));
  }
  const CombinedEstimate c =
      with_firmware(audit, f.sigma, edges ? edges->total_v_per_v.data() : nullptr,
                    edges ? edges->sigma_v_per_v : 0.0,
                    "drive_feedthrough (x re, x im, y re, y im)", "V/V", comments);
  set(out, "feedthrough_x_re_v_per_v", c.value[0], c.sigma, 1.0);
  set(out, "feedthrough_x_im_v_per_v", c.value[1], c.sigma, 1.0);
  set(out, "feedthrough_y_re_v_per_v", c.value[2], c.sigma, 1.0);
  set(out, "feedthrough_y_im_v_per_v", c.value[3], c.sigma, 1.0);
}

void set_thermal_damping(fw::CalibrationFile& out, const Finding& f,
                         const CalibrationWriterOptions& opt, std::vector<std::string>& comments) {
  const auto& check = opt.firmware.thermal_damping;
  const double audit[1] = {f.value};
  const CombinedEstimate c = with_firmware(
      audit, f.sigma, check ? &check->per_c : nullptr, check ? check->sigma_per_c : 0.0,
      "thermal_damping (the firmware's: its damping model check)", "/degC", comments);
  set(out, "thermal_damping_per_c", c.value[0], c.sigma, 1.0);
}

// The pickoff map's parts: the effect, its key, the catalogue unit's scale
// to SI, and the firmware's part (SI) of the self-calibration's map.
struct PickoffPart {
  Effect effect;
  const char* key;
  double scale;
  FirmwarePickoffPart FirmwarePickoffMap::*part;
};
constexpr PickoffPart kPickoffParts[3] = {
    {Effect::pickoff_gain_mismatch, "pickoff_y_gain", 1.0, &FirmwarePickoffMap::gain},
    {Effect::pickoff_misalignment, "pickoff_y_misalignment_rad", kDegToRad,
     &FirmwarePickoffMap::misalignment_rad},
    {Effect::pickoff_phase_mismatch, "pickoff_y_phase_rad", kDegToRad,
     &FirmwarePickoffMap::phase_rad}};

// The catalogue's unit after a value ("" for the gain's "-").
const char* unit_text(Effect e) {
  const char* u = effect_info(e).unit;
  return std::string_view(u) == "-" ? "" : u;
}

const PickoffPart& pickoff_part(Effect e) {
  for (const PickoffPart& p : kPickoffParts)
    if (p.effect == e) return p;
  throw std::logic_error("not a pickoff effect");
}

// A pickoff part: the audit's finding and, where the firmware's
// self-calibration read the whole map (referred to the raw pickoffs, as the
// audit's finding on a recording without a map in force), its part, the
// two combined in the catalogue's unit.
void set_pickoff(fw::CalibrationFile& out, const Finding& f, const CalibrationWriterOptions& opt,
                 std::vector<std::string>& comments) {
  const PickoffPart& p = pickoff_part(f.effect);
  const double audit[1] = {f.value};
  double firmware = 0.0;
  double firmware_sigma = 0.0;
  if (const auto& map = opt.firmware.pickoff) {
    firmware = ((*map).*p.part).value / p.scale;
    firmware_sigma = ((*map).*p.part).sigma / p.scale;
  }
  const CombinedEstimate c = with_firmware(
      audit, std::fabs(f.sigma), opt.firmware.pickoff ? &firmware : nullptr, firmware_sigma,
      std::string(effect_info(f.effect).id) + " (the firmware's: its pickoff self-calibration)",
      unit_text(f.effect), comments);
  set(out, p.key, c.value[0], c.sigma, p.scale);
}

void apply_finding(fw::CalibrationFile& out, const Finding& f, const AuditResult& r,
                   const CalibrationWriterOptions& opt, std::vector<std::string>& comments) {
  switch (f.effect) {
    case Effect::pickoff_gain_mismatch:
    case Effect::pickoff_phase_mismatch:
    case Effect::pickoff_misalignment: set_pickoff(out, f, opt, comments); break;
    case Effect::duffing_stiffness: set(out, "duffing_hz_per_v2", f.value, f.sigma, 1.0); break;
    case Effect::nonlinear_damping:
      set(out, "nonlinear_damping_per_v2", f.value, f.sigma, 1.0);
      break;
    case Effect::thermal_frequency:
      set(out, "thermal_frequency_ppm_per_c", f.value, f.sigma, 1.0);
      set(out, "temperature_ref_c", r.temp_ref_c, 0.0, 1.0);
      break;
    case Effect::thermal_damping:
      set_thermal_damping(out, f, opt, comments);
      set(out, "temperature_ref_c", r.temp_ref_c, 0.0, 1.0);
      break;
    case Effect::electrostatic_spring:
      set(out, "electrostatic_spring_hz_per_v2", f.value, f.sigma, 1.0);
      break;
    case Effect::drive_feedthrough: set_feedthrough(out, f, opt, comments); break;
    case Effect::gap_harmonics:
      set(out, "gap_eps_p", f.gap_eps_pq_sigma[0], f.gap_eps_pq_sigma[2], 1.0);
      set(out, "gap_eps_q", f.gap_eps_pq_sigma[1], f.gap_eps_pq_sigma[3], 1.0);
      break;
  }
}

bool found(const AuditResult& r, Effect e) {
  return std::any_of(r.findings.begin(), r.findings.end(),
                     [e](const Finding& f) { return f.effect == e; });
}

// The firmware's estimates of an effect the audit did not accept: said, not
// applied (the file holds accepted findings only).
void firmware_without_finding(const AuditResult& r, const CalibrationWriterOptions& opt,
                              std::vector<std::string>& comments) {
  if (const auto& e = opt.firmware.feedthrough; e && !found(r, Effect::drive_feedthrough)) {
    const auto& k = e->total_v_per_v;
    comments.push_back(fmt("not applied: the firmware's switch-off step check reads a drive "
                           "feedthrough x %.4g %+.4gi",
                           k[0], k[1]) +
                       fmt(", y %.4g %+.4gi", k[2], k[3]) +
                       fmt(" +- %.2g V/V; the audit found none", e->sigma_v_per_v));
  }
  if (const auto& map = opt.firmware.pickoff) {
    for (const PickoffPart& p : kPickoffParts) {
      if (found(r, p.effect)) continue;
      const FirmwarePickoffPart& part = (*map).*p.part;
      std::string line = "not applied: the firmware's pickoff self-calibration reads ";
      line += effect_info(p.effect).id;
      line += fmt(" %.6g +- %.2g", part.value / p.scale, part.sigma / p.scale);
      if (*unit_text(p.effect) != '\0') line.append(" ").append(unit_text(p.effect));
      line += "; the audit found none";
      comments.push_back(line);
    }
  }
  if (const auto& e = opt.firmware.thermal_damping; e && !found(r, Effect::thermal_damping)) {
    comments.push_back(
        fmt("not applied: the firmware's damping model check reads a thermal "
            "damping %.4g +- %.2g /degC; the audit found none",
            e->per_c, e->sigma_per_c));
  }
}

}  // namespace

CalibrationFromAudit calibration_from_audit(const AuditResult& r, const std::string& source,
                                            const CalibrationWriterOptions& opt) {
  CalibrationFromAudit out;
  auto& c = out.comments;
  c.push_back("hrg calibration from `hrg audit " + source + "` (verdict: " + r.verdict + ")");
  c.push_back("values are the audit's accepted findings; *_sigma is one standard deviation;");
  c.push_back("a key left at 0 was not found (nothing is corrected for it)");
  for (const Finding& f : r.findings)
    apply_finding(out.file, f, r, opt, c);
  for (const Alternative& a : r.alternatives) {
    c.push_back(std::string("not applied: ") + effect_info(a.effect).id + " " +
                fmt("%.4g", a.value) + " " + effect_info(a.effect).unit +
                " (an alternative, not an accepted finding: " + a.note + ")");
  }
  if (r.verdict == "unexplained") {
    c.push_back("not applied: structure the catalogue does not explain (" + r.unexplained_note +
                "); the firmware has no correction for it");
  }
  if (r.verdict == "ambiguous" && !r.ambiguity_experiment.empty()) {
    c.push_back("ambiguous: " + r.ambiguity_experiment);
  }
  firmware_without_finding(r, opt, c);
  c.push_back(
      "not in the file: the baseline (frequency, damping and its anisotropy, split, "
      "angular gain) is what the estimator identifies online, not a calibration");
  return out;
}

void write_calibration_file(const std::string& path, const AuditResult& r,
                            const std::string& source, const CalibrationWriterOptions& opt) {
  const CalibrationFromAudit c = calibration_from_audit(r, source, opt);
  fw::save_calibration(path, c.file, c.comments, {});
}

}  // namespace hrg::audit
