// SPDX-License-Identifier: MIT
// The sections of the data sheet, one per test series.
#include <cmath>

#include "characterize/datasheet.hpp"
#include "sheet_json.hpp"

namespace hrg::characterize {

using sheet::fmt;
using sheet::kDeg;
using sheet::kNone;
using sheet::Series;

void DataSheet::noise(std::span<const AllanPoint> curve, const NoiseTerms& t, double confidence) {
  begin_section("noise", "Noise", "IEEE Std 952 annex C");
  const std::string ci = fmt("%.1f %% chi-square interval", 100.0 * confidence);
  w_.begin_array("figures");
  figure("Angle random walk", arw_deg_per_sqrt_h(t.arw.value), arw_deg_per_sqrt_h(t.arw.lo),
         arw_deg_per_sqrt_h(t.arw.hi), kNone, "deg/sqrt(h)",
         "on the -1/2 slope, read at tau = 1 s (rests on tau = " + fmt("%g s", t.arw.at_tau_s) +
             "); " + ci + sheet::resolved(t.arw));
  figure("Bias instability", rate_deg_per_h(t.bias_instability.value),
         rate_deg_per_h(t.bias_instability.lo), rate_deg_per_h(t.bias_instability.hi), kNone,
         "deg/h",
         "flat minimum at tau = " + fmt("%g s", t.bias_instability.at_tau_s) +
             " divided by 0.664 = sqrt(2 ln2 / pi); " + ci + sheet::resolved(t.bias_instability));
  figure("Rate random walk", rrw_deg_per_h_per_sqrt_h(t.rate_random_walk.value),
         rrw_deg_per_h_per_sqrt_h(t.rate_random_walk.lo),
         rrw_deg_per_h_per_sqrt_h(t.rate_random_walk.hi), kNone, "deg/h/sqrt(h)",
         "on the +1/2 slope, read at tau = 3 s (rests on tau = " +
             fmt("%g s", t.rate_random_walk.at_tau_s) + "); " + ci +
             sheet::resolved(t.rate_random_walk));
  w_.end_array();
  std::vector<std::vector<std::string>> rows;
  Series s{"overlapping ADEV, " + ci, "errorbar", {}, {}, {}, {}};
  for (const AllanPoint& p : curve) {
    s.x.push_back(p.tau_s);
    s.y.push_back(rate_deg_per_h(p.adev));
    s.lo.push_back(rate_deg_per_h(p.adev_lo));
    s.hi.push_back(rate_deg_per_h(p.adev_hi));
    rows.push_back({fmt("%g", p.tau_s), fmt("%.4g", rate_deg_per_h(p.adev)),
                    fmt("%.4g", rate_deg_per_h(p.adev_lo)), fmt("%.4g", rate_deg_per_h(p.adev_hi)),
                    fmt("%.1f", p.edf), std::to_string(p.alpha)});
  }
  w_.begin_array("tables");
  sheet::table(w_, "Allan deviation",
               {"tau (s)", "ADEV (deg/h)", "lower", "upper", "edf", "noise alpha"}, rows);
  w_.end_array();
  w_.begin_array("plots");
  sheet::plot(w_, "allan", "Allan deviation of the output rate", "tau (s)", "ADEV (deg/h)", true,
              true, {s});
  w_.end_array();
  w_.end_object();
}

void DataSheet::scale_factor(std::span<const RateStep> steps, const ScaleFactorSeries& sf,
                             std::span<const double> true_angle_rad,
                             std::span<const double> readout_rad,
                             const AngleDependentScaleFactor& adsf) {
  begin_section("scale_factor", "Scale factor series", "IEEE Std 1431 12.9");
  w_.begin_array("figures");
  const std::string span = fmt("+-%.0f deg/s full scale, ", sf.full_scale_rad_s * kDeg) +
                           fmt("%.2f decades", sf.decades);
  figure("Scale factor error", sf.k_error_ppm, kNone, kNone, sf.sigma_k_error_ppm, "ppm",
         "best-fit straight line, " + span + fmt(", K = %.8f", sf.k));
  figure("Nonlinearity", sf.nonlinearity_ppm, kNone, kNone, sf.sigma_nonlinearity_ppm,
         "ppm of full scale",
         fmt("largest departure from the best line (asymmetry included), at %.0f deg/s",
             sf.worst_input_rad_s * kDeg));
  figure("Asymmetry", sf.asymmetry_ppm, kNone, kNone, sf.sigma_asymmetry_ppm, "ppm",
         "(K+ - K-) / K");
  figure("Angle-dependent readout error (4 theta)", adsf.amplitude_deg, kNone, kNone,
         adsf.sigma_amplitude_deg, "deg",
         fmt("amplitude over whole turns; local scale factor swings +-%.0f ppm",
             adsf.scale_swing_ppm));
  w_.end_array();
  std::vector<std::vector<std::string>> rows;
  Series dev{"departure from the best line", "points", {}, {}, {}, {}};
  for (std::size_t i = 0; i < steps.size(); ++i) {
    dev.x.push_back(steps[i].input_rad_s * kDeg);
    dev.y.push_back(sf.deviation_ppm[i]);
    rows.push_back({fmt("%.3f", steps[i].input_rad_s * kDeg),
                    fmt("%.6f", steps[i].output_rad_s * kDeg), fmt("%.2f", sf.deviation_ppm[i])});
  }
  w_.begin_array("tables");
  sheet::table(w_, "Rate-table steps", {"input (deg/s)", "output (deg/s)", "departure (ppm FS)"},
               rows);
  w_.end_array();
  Series err{"readout error", "line", {}, {}, {}, {}};
  Series fit{"fit: offset + slope + 4 theta", "line", {}, {}, {}, {}};
  const Harmonic& h = adsf.fit.harmonics.empty() ? Harmonic{} : adsf.fit.harmonics.front();
  for (std::size_t i = 0; i < true_angle_rad.size() && i < readout_rad.size(); ++i) {
    const double th = true_angle_rad[i];
    err.x.push_back(th * kDeg);
    err.y.push_back((readout_rad[i] - th) * kDeg);
    fit.x.push_back(th * kDeg);
    fit.y.push_back((adsf.fit.offset + adsf.fit.slope * th + h.a_sin * std::sin(4 * th) +
                     h.b_cos * std::cos(4 * th)) *
                    kDeg);
  }
  w_.begin_array("plots");
  sheet::plot(w_, "sf_departure", "Scale factor: departure from the best line", "input (deg/s)",
              "departure (ppm of full scale)", false, false, {dev});
  sheet::plot(w_, "readout_4theta", "Readout error over whole turns", "pattern angle (deg)",
              "readout - true (deg)", false, false, {err, fit});
  w_.end_array();
  w_.end_object();
}

}  // namespace hrg::characterize
