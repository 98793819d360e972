// SPDX-License-Identifier: MIT
// The procedures' measured figures as data sheet sections (the analysis
// sections of DataSheet where they exist, assembled ones for the parked-angle
// bias, the rate limits and the run-down).
#include <cmath>
#include <cstdio>
#include <limits>

#include "common.hpp"
#include "sheet_sections.hpp"

namespace hrg::characterize::proc {

namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

std::string num(const char* f, double v) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

SheetFigure fig(std::string name, double value, double sigma, std::string unit, std::string note) {
  return {std::move(name), value, kNone, kNone, sigma, std::move(unit), std::move(note)};
}

}  // namespace

void add_angle_dependent_bias(DataSheet& sheet, const DriftResult& d) {
  const std::vector<SheetFigure> figs{
      fig("ADB 4 theta amplitude, raw", d.adb_raw.amplitude(),
          std::hypot(d.adb_raw.sigma_a, d.adb_raw.sigma_b), "deg/h",
          "b0 + a sin 4theta + b cos 4theta over the parked angles"),
      fig("ADB 4 theta amplitude, compensated", d.adb_comp.amplitude(),
          std::hypot(d.adb_comp.sigma_a, d.adb_comp.sigma_b), "deg/h", "drift model applied"),
      fig("ADB 4 theta amplitude, resonator model", d.adb_model.amplitude(), kNone, "deg/h",
          "the true D / K at the parked angles"),
      fig("ADB mean bias, compensated", d.adb_comp.b0, d.adb_comp.sigma_b0, "deg/h", ""),
  };
  SheetTable parks{
      "Parked angles", {"theta (deg)", "raw (deg/h)", "comp. (deg/h)", "model (deg/h)"}, {}};
  SheetSeries raw{"raw", "points", {}, {}, {}, {}}, comp{"compensated", "points", {}, {}, {}, {}};
  SheetSeries model{"true -D/K", "line", {}, {}, {}, {}};
  for (const sim_run::ParkResult& p : d.parks) {
    const double th = p.theta_rad / kDeg;
    parks.rows.push_back({num("%.2f", th), num("%.3f", p.bias_raw_dph),
                          num("%.4f", p.bias_comp_dph), num("%.3f", p.bias_model_dph)});
    raw.x.push_back(th);
    raw.y.push_back(p.bias_raw_dph);
    comp.x.push_back(th);
    comp.y.push_back(p.bias_comp_dph);
    model.x.push_back(th);
    model.y.push_back(p.bias_model_dph);
  }
  const std::vector<SheetTable> tables{parks};
  const std::vector<SheetPlot> plots{{"adb",
                                      "Angle-dependent bias",
                                      "pattern angle (deg)",
                                      "bias (deg/h)",
                                      false,
                                      false,
                                      {raw, comp, model}}};
  sheet.section("adb", "Angle-dependent bias", "IEEE Std 1431 12.11", figs, tables, plots);
}

void add_limits(DataSheet& sheet, const LimitsResult& l) {
  const std::vector<SheetFigure> figs{
      fig("Rate threshold, raw", l.measured_raw_dph, kNone, "deg/h",
          num("zero of the raw output rate at the least favourable angle %.1f deg",
              l.theta_hold_deg)),
      fig("Rate threshold, raw, closed form nu dmu / K", l.closed_form_dph, kNone, "deg/h",
          num("true D / K at that angle: %.2f deg/h", l.predicted_raw_dph)),
      fig("Rate threshold, compensated", l.measured_comp_dph, kNone, "deg/h",
          num("predicted by the residual drift (true - model) / K: %.3f deg/h",
              l.predicted_comp_dph)),
      fig(l.limit_reached ? "Largest input rate followed" : "Largest input rate followed (>=)",
          l.largest_followed_dps, kNone, "deg/s",
          l.limit_reached ? "the next step was not followed (1000 ppm, valid output)"
                          : "every tested rate was followed"),
  };
  SheetTable steps{
      "Threshold steps", {"input (deg/h)", "raw output (deg/h)", "comp. output (deg/h)"}, {}};
  SheetSeries raw{"raw", "points", {}, {}, {}, {}}, comp{"compensated", "points", {}, {}, {}, {}};
  for (const ThresholdStep& s : l.threshold_steps) {
    steps.rows.push_back(
        {num("%.2f", s.input_dph), num("%.2f", s.raw_dph), num("%.3f", s.comp_dph)});
    raw.x.push_back(s.input_dph);
    raw.y.push_back(s.raw_dph);
    comp.x.push_back(s.input_dph);
    comp.y.push_back(s.comp_dph);
  }
  SheetTable rates{
      "Input rate steps", {"input (deg/s)", "output / input - 1 (ppm)", "followed"}, {}};
  for (std::size_t i = 0; i < l.rate_limit_steps.size(); ++i) {
    const RateStep& s = l.rate_limit_steps[i];
    rates.rows.push_back({num("%.1f", s.input_rad_s / kDeg),
                          num("%.1f", (s.output_rad_s / s.input_rad_s - 1.0) * 1e6),
                          l.followed[i] ? "yes" : "no"});
  }
  const std::vector<SheetTable> tables{steps, rates};
  const std::vector<SheetPlot> plots{{"threshold",
                                      "Output rate near the threshold",
                                      "input rate (deg/h)",
                                      "output rate (deg/h)",
                                      false,
                                      false,
                                      {raw, comp}}};
  sheet.section("limits", "Input rate limits and rate threshold", "IEEE Std 1431 12.10", figs,
                tables, plots);
}

void add_rundown(DataSheet& sheet, const RundownResult& r) {
  const std::vector<SheetFigure> figs{
      fig("Run-down time", r.rundown_s, kNone, "s",
          num("excitation off until the amplitude reaches the noise floor %.3g V",
              r.noise_floor_v)),
      fig("Run-down time, closed form", r.rundown_predicted_s, kNone, "s",
          "free decay on the two damping axes from the same start"),
      fig("Free-decay rate", r.decay_rate_per_s, kNone, "1/s",
          num("closed form over the record: %.5g 1/s", r.decay_rate_predicted_per_s)),
      fig("Angle storage: readout error, largest", r.readout_error_max_deg, kNone, "deg",
          "read pattern angle minus the true one over the record"),
  };
  SheetSeries meas{"measured", "line", {}, {}, {}, {}},
      model{"closed form", "line", {}, {}, {}, {}};
  const std::size_t stride = std::max<std::size_t>(1, r.t_s.size() / 400);
  for (std::size_t i = 0; i < r.t_s.size(); i += stride) {
    meas.x.push_back(r.t_s[i]);
    meas.y.push_back(r.amplitude_v[i]);
    model.x.push_back(r.t_s[i]);
    model.y.push_back(r.model_v[i]);
  }
  const std::vector<SheetPlot> plots{{"rundown",
                                      "Free decay, excitation off",
                                      "time (s)",
                                      "amplitude (V)",
                                      false,
                                      true,
                                      {meas, model}}};
  sheet.section("rundown", "Angle storage and run-down", "IEEE Std 1431 12.13, 12.14", figs, {},
                plots);
}

}  // namespace hrg::characterize::proc
