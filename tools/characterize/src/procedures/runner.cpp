// SPDX-License-Identifier: MIT
// `hrg characterize --test`: the procedures in order, each adding its data
// sheet sections and one line of figures.
#include <algorithm>
#include <array>
#include <cstdio>
#include <stdexcept>

#include "common.hpp"
#include "sheet_sections.hpp"

namespace hrg::characterize {

namespace {

constexpr std::array<std::string_view, 5> kNames{"scale_factor", "drift", "limits", "noise",
                                                 "rundown"};

std::string line(const char* f, auto... v) {
  char buf[512];
  std::snprintf(buf, sizeof buf, f, v...);
  return buf;
}

bool wanted(std::span<const std::string> names, std::string_view name) {
  return std::any_of(names.begin(), names.end(),
                     [&](const std::string& n) { return n == "all" || n == name; });
}

void add_time(ProcedureReport& rep, double wall_s, double sim_s) {
  rep.wall_s += wall_s;
  rep.sim_s += sim_s;
}

// Each procedure: its run, its data sheet sections, its line of figures.
void scale_factor_part(const ProcedureOptions& o, DataSheet& sheet, ProcedureReport& rep) {
  const ScaleFactorResult r = run_scale_factor(o);
  sheet.scale_factor(r.steps, r.series, r.true_theta_rad, r.read_theta_rad, r.readout);
  rep.lines.push_back(
      line("scale_factor: K error %.2f ppm, nonlinearity %.2f ppm FS, asymmetry "
           "%.2f ppm, 4 theta readout %.4g deg (%.0f s simulated, %.1f s wall)",
           r.series.k_error_ppm, r.series.nonlinearity_ppm, r.series.asymmetry_ppm,
           r.readout.amplitude_deg, r.sim_s, r.wall_s));
  add_time(rep, r.wall_s, r.sim_s);
}

DriftResult drift_part(const ProcedureOptions& o, bool drift, DataSheet& sheet,
                       ProcedureReport& rep) {
  const DriftResult d = drift ? run_drift(o) : run_angle_dependent_bias(o);
  proc::add_angle_dependent_bias(sheet, d);
  if (drift) {
    sheet.drift(d.turn_on_bias_dph, d.repeatability, d.temperature_c, d.temperature_bias_dph,
                d.temperature);
  }
  std::string figures =
      line("drift: ADB raw %.3f, comp %.3f deg/h", d.adb_raw.amplitude(), d.adb_comp.amplitude());
  if (drift) {
    figures += line("; repeatability %.4f deg/h over %zu; temperature %.4g deg/h/degC",
                    d.repeatability.std, d.repeatability.runs, d.temperature.slope_per_degc);
  }
  rep.lines.push_back(figures + line(" (%.0f s simulated, %.1f s wall)", d.sim_s, d.wall_s));
  add_time(rep, d.wall_s, d.sim_s);
  return d;
}

void limits_part(const ProcedureOptions& o, const DriftResult& d, DataSheet& sheet,
                 ProcedureReport& rep) {
  const LimitsResult l = run_limits(o, d);
  proc::add_limits(sheet, l);
  rep.lines.push_back(
      line("limits: threshold raw %.2f deg/h (closed form %.2f), compensated "
           "%.3f deg/h (predicted %.3f); rates followed up to %.0f deg/s "
           "(%.0f s simulated, %.1f s wall)",
           l.measured_raw_dph, l.closed_form_dph, l.measured_comp_dph, l.predicted_comp_dph,
           l.largest_followed_dps, l.sim_s, l.wall_s));
  add_time(rep, l.wall_s, l.sim_s);
}

void noise_part(const ProcedureOptions& o, DataSheet& sheet, ProcedureReport& rep) {
  const NoiseResult n = run_noise(o);
  sheet.noise(n.curve, n.terms, 0.683);
  rep.lines.push_back(
      line("noise: ARW %.4g deg/sqrt(h)%s, bias instability %.4g deg/h over %.0f s "
           "(%.0f s simulated, %.1f s wall)",
           arw_deg_per_sqrt_h(n.terms.arw.value), n.terms.arw.on_slope ? "" : " (upper bound)",
           rate_deg_per_h(n.terms.bias_instability.value), n.record_s, n.sim_s, n.wall_s));
  add_time(rep, n.wall_s, n.sim_s);
}

void rundown_part(const ProcedureOptions& o, DataSheet& sheet, ProcedureReport& rep) {
  const RundownResult r = run_rundown(o);
  proc::add_rundown(sheet, r);
  rep.lines.push_back(
      line("rundown: %.0f s (closed form %.0f s), decay %.5g 1/s (closed form "
           "%.5g), readout error <= %.3g deg (%.0f s simulated, %.1f s wall)",
           r.rundown_s, r.rundown_predicted_s, r.decay_rate_per_s, r.decay_rate_predicted_per_s,
           r.readout_error_max_deg, r.sim_s, r.wall_s));
  add_time(rep, r.wall_s, r.sim_s);
}

}  // namespace

std::span<const std::string_view> procedure_names() { return kNames; }

ProcedureReport run_procedures(std::span<const std::string> names, const ProcedureOptions& o) {
  for (const std::string& n : names) {
    if (n != "all" && std::find(kNames.begin(), kNames.end(), n) == kNames.end())
      throw std::invalid_argument("unknown test '" + n +
                                  "' (scale_factor, drift, limits, noise, rundown or all)");
  }
  ProcedureReport rep;
  DataSheet sheet(o.scenario.empty() ? "HRG data sheet: the default gyro (simulated)"
                                     : "HRG data sheet: scenario " + o.scenario);
  if (wanted(names, "scale_factor")) scale_factor_part(o, sheet, rep);
  // The rate threshold is read at the least favourable angle of the parked-angle test.
  const bool drift = wanted(names, "drift"), limits = wanted(names, "limits");
  if (drift || limits) {
    const DriftResult d = drift_part(o, drift, sheet, rep);
    if (limits) limits_part(o, d, sheet, rep);
  }
  if (wanted(names, "noise")) noise_part(o, sheet, rep);
  if (wanted(names, "rundown")) rundown_part(o, sheet, rep);
  rep.sheet_json = sheet.finish();
  return rep;
}

}  // namespace hrg::characterize
