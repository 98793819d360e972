// SPDX-License-Identifier: MIT
// The drift-rate and limits sections of the data sheet.
#include "characterize/datasheet.hpp"
#include "sheet_json.hpp"

namespace hrg::characterize {

using sheet::fmt;
using sheet::kNone;
using sheet::Series;

void DataSheet::drift(std::span<const double> turn_on_bias_dph, const Repeatability& rep,
                      std::span<const double> temperature_degc, std::span<const double> bias_dph,
                      const TemperatureSlope& temp) {
  begin_section("drift", "Drift rate series", "IEEE Std 1431 12.11");
  w_.begin_array("figures");
  figure("Bias (mean of turn-ons)", rep.mean, kNone, kNone, rep.sigma_mean, "deg/h",
         std::to_string(rep.runs) + " turn-ons");
  figure("Bias repeatability (1 sigma)", rep.std, rep.std_lo, rep.std_hi, kNone, "deg/h",
         "standard deviation over turn-ons; chi-square interval with N - 1 dof");
  figure("Bias temperature sensitivity", temp.slope_per_degc, kNone, kNone,
         temp.sigma_slope_per_degc, "deg/h/degC",
         fmt("least-squares slope, residual rms %.3g deg/h", temp.residual_rms));
  w_.end_array();
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < turn_on_bias_dph.size(); ++i)
    rows.push_back({std::to_string(i + 1), fmt("%.4f", turn_on_bias_dph[i])});
  w_.begin_array("tables");
  sheet::table(w_, "Turn-on biases", {"turn-on", "bias (deg/h)"}, rows);
  w_.end_array();
  Series meas{"bias", "points", {}, {}, {}, {}};
  Series line{"fitted slope", "line", {}, {}, {}, {}};
  for (std::size_t i = 0; i < temperature_degc.size() && i < bias_dph.size(); ++i) {
    meas.x.push_back(temperature_degc[i]);
    meas.y.push_back(bias_dph[i]);
    line.x.push_back(temperature_degc[i]);
    line.y.push_back(temp.bias_at_mean +
                     temp.slope_per_degc * (temperature_degc[i] - temp.mean_temperature_degc));
  }
  w_.begin_array("plots");
  sheet::plot(w_, "bias_temperature", "Bias against temperature", "temperature (degC)",
              "bias (deg/h)", false, false, {meas, line});
  w_.end_array();
  w_.end_object();
}

void DataSheet::limits(const Limits& l) {
  begin_section("limits", "Rate threshold and run-down", "IEEE Std 1431 12.10, 12.14");
  w_.begin_array("figures");
  figure("Rate threshold, raw", l.threshold_raw_dph, kNone, kNone, kNone, "deg/h",
         "the pattern is caught below K Omega = nu dmu; " + l.note);
  figure("Rate threshold, compensated", l.threshold_compensated_dph, kNone, kNone, kNone, "deg/h",
         "with the identified damping anisotropy removed");
  figure("Run-down time", l.rundown_s, kNone, kNone, kNone, "s",
         "excitation off until the amplitude reaches the noise floor");
  w_.end_array();
  w_.end_object();
}

}  // namespace hrg::characterize
