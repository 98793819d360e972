// SPDX-License-Identifier: MIT
#include "description.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace hrg::audit::detail {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadToDeg = 180.0 / kPi;

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0, double e = 0.0) {
  char buf[320];
  std::snprintf(buf, sizeof buf, f, a, b, c, e);
  return buf;
}

// Range of a_A^2 and of the temperature over the free-decay blocks.
struct Ranges {
  double a2_lo = 1e300, a2_hi = 0.0, t_lo = 1e300, t_hi = -1e300, hours = 0.0;
};

Ranges ranges_of(const Dataset& d) {
  Ranges r;
  for (const auto& b : d.blocks) {
    r.a2_lo = std::min(r.a2_lo, b.a2_v2), r.a2_hi = std::max(r.a2_hi, b.a2_v2);
    r.t_lo = std::min(r.t_lo, b.temp_c), r.t_hi = std::max(r.t_hi, b.temp_c);
  }
  if (!d.t_s.empty()) r.hours = (d.t_s.back() - d.t_s.front()) / 3600.0;
  return r;
}

// Amplitude and angle (deg of pattern angle) of c cos 8th + s sin 8th.
double amp8(const Params& p, int c) { return std::hypot(p[c], p[c + 1]); }
double angle8_deg(const Params& p, int c) { return std::atan2(p[c + 1], p[c]) / 8.0 * kRadToDeg; }

}  // namespace

std::span<const GenericTerm> generic_terms() {
  static constexpr std::array<GenericTerm, 14> kTerms{{
      {"frequency_vs_amplitude4", {kGFreqA4, 0}, 1},
      {"damping_vs_amplitude4", {kGDampA4, 0}, 1},
      {"frequency_vs_temperature2", {kGFreqT2, 0}, 1, true},
      {"damping_vs_temperature2", {kGDampT2, 0}, 1, true},
      {"frequency_drift", {kGFreqTime, 0}, 1},
      {"damping_drift", {kGDampTime, 0}, 1},
      {"damping_vs_angle8", {kGDamp8C, kGDamp8S}, 2},
      {"frequency_vs_angle8", {kGFreq8C, kGFreq8S}, 2},
      {"gain_ratio_drift", {kGGainTime, 0}, 1},
      {"phase_drift", {kGPhaseTime, 0}, 1},
      {"gain_ratio_vs_temperature", {kGGainTemp, 0}, 1, true},
      {"offset_x", {kGOffXRe, kGOffXIm}, 2},
      {"offset_y", {kGOffYRe, kGOffYIm}, 2},
      {"frequency_with_excitation", {kGFreqExc, 0}, 1, false, true},
  }};
  return kTerms;
}

namespace {

// Terms of the resonator: frequency and damping against amplitude,
// temperature, time and pattern angle ("" for a pickoff or excitation term).
std::string describe_resonator_term(const std::string& id, const Dataset& d, const Ranges& r,
                                    const Params& p, const Params& sg) {
  const double a4_span = r.a2_hi * r.a2_hi - r.a2_lo * r.a2_lo;
  if (id == "frequency_vs_amplitude4") {
    return fmt(
        "the wave frequency changes with the fourth power of the amplitude: %.3g +/- %.2g "
        "Hz/V^4 (%.3g mHz between the smallest and largest free-decay amplitude)",
        p[kGFreqA4], sg[kGFreqA4], p[kGFreqA4] * a4_span * 1e3);
  }
  if (id == "damping_vs_amplitude4") {
    return fmt(
        "the damping changes with the fourth power of the amplitude: %.3g +/- %.2g per V^4 "
        "(%.3g %% between the smallest and largest free-decay amplitude)",
        p[kGDampA4], sg[kGDampA4], 100.0 * p[kGDampA4] * a4_span);
  }
  if (id == "frequency_vs_temperature2") {
    return fmt(
        "the wave frequency changes with the square of the temperature offset from %.2f "
        "degC: %.3g +/- %.2g ppm/degC^2",
        d.temp_ref_c, p[kGFreqT2], sg[kGFreqT2]);
  }
  if (id == "damping_vs_temperature2") {
    return fmt(
        "the damping changes with the square of the temperature offset from %.2f degC: "
        "%.3g +/- %.2g per degC^2",
        d.temp_ref_c, p[kGDampT2], sg[kGDampT2]);
  }
  if (id == "frequency_drift") {
    return fmt(
        "the wave frequency drifts by %.3g +/- %.2g mHz per hour (%.3g mHz over the "
        "recording)",
        p[kGFreqTime] * 1e3, sg[kGFreqTime] * 1e3, p[kGFreqTime] * r.hours * 1e3);
  }
  if (id == "damping_drift") {
    return fmt("the damping drifts by %.3g +/- %.2g %% per hour (%.3g %% over the recording)",
               100.0 * p[kGDampTime], 100.0 * sg[kGDampTime], 100.0 * p[kGDampTime] * r.hours);
  }
  if (id == "damping_vs_angle8") {
    return fmt(
        "the damping varies with the pattern angle as %.3g %% (+/- %.2g) cos 8(theta - "
        "%.1f deg), beyond the 4-theta anisotropy",
        100.0 * amp8(p, kGDamp8C), 100.0 * std::max(sg[kGDamp8C], sg[kGDamp8S]),
        angle8_deg(p, kGDamp8C));
  }
  if (id == "frequency_vs_angle8") {
    return fmt(
        "the wave frequency varies with the pattern angle as %.3g mHz (+/- %.2g) cos "
        "8(theta - %.1f deg), beyond the 4-theta split",
        amp8(p, kGFreq8C) * 1e3, std::max(sg[kGFreq8C], sg[kGFreq8S]) * 1e3,
        angle8_deg(p, kGFreq8C));
  }
  return "";
}

// Terms of the pickoffs and of the excitation state.
std::string describe_pickoff_term(const std::string& id, const Ranges& r, const Params& p,
                                  const Params& sg) {
  if (id == "gain_ratio_drift") {
    return fmt(
        "the y/x pickoff gain ratio changes by %.3g +/- %.2g per hour (%.3g over the "
        "recording)",
        p[kGGainTime], sg[kGGainTime], p[kGGainTime] * r.hours);
  }
  if (id == "phase_drift") {
    return fmt(
        "the y pickoff phase changes by %.3g +/- %.2g deg per hour (%.3g deg over the "
        "recording)",
        p[kGPhaseTime] * kRadToDeg, sg[kGPhaseTime] * kRadToDeg,
        p[kGPhaseTime] * r.hours * kRadToDeg);
  }
  if (id == "gain_ratio_vs_temperature") {
    return fmt(
        "the y/x pickoff gain ratio changes by %.3g +/- %.2g per degC (%.3g over "
        "%.2f degC)",
        p[kGGainTemp], sg[kGGainTemp], p[kGGainTemp] * (r.t_hi - r.t_lo), r.t_hi - r.t_lo);
  }
  if (id == "offset_x" || id == "offset_y") {
    const int c = id == "offset_x" ? kGOffXRe : kGOffXRe + 2;
    return fmt(id == "offset_x"
                   ? "the x pickoff carries a constant offset of %.3g V (cx_v %.3g V, sx_v %.3g "
                     "V; +/- %.2g V)"
                   : "the y pickoff carries a constant offset of %.3g V (cy_v %.3g V, sy_v %.3g "
                     "V; +/- %.2g V)",
               std::hypot(p[c], p[c + 1]), p[c], -p[c + 1], std::max(sg[c], sg[c + 1]));
  }
  if (id == "frequency_with_excitation") {
    return fmt(
        "the wave frequency is %.3g +/- %.2g mHz higher while the excitation is on, "
        "whatever the pump voltage",
        p[kGFreqExc] * 1e3, sg[kGFreqExc] * 1e3);
  }
  return id;
}

}  // namespace

std::string describe_term(const GenericTerm& t, const Dataset& d, const Params& p,
                          const Params& sigma) {
  const Ranges r = ranges_of(d);
  const std::string text = describe_resonator_term(t.id, d, r, p, sigma);
  return text.empty() ? describe_pickoff_term(t.id, r, p, sigma) : text;
}

}  // namespace hrg::audit::detail
