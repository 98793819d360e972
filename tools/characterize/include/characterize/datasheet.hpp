// SPDX-License-Identifier: MIT
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "characterize/allan.hpp"
#include "characterize/drift_series.hpp"
#include "characterize/noise_terms.hpp"
#include "characterize/scale_factor.hpp"
#include "sim_run/json.hpp"

namespace hrg::characterize {

// Pieces of a section that a caller assembles itself (a test procedure's
// measured figures): figures, data tables and plots, as in the JSON below.
struct SheetFigure {
  std::string name;
  double value = 0.0, lo = 0.0, hi = 0.0, sigma = 0.0;  // NaN: not stated (null)
  std::string unit, note;
};
struct SheetTable {
  std::string title;
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
};
struct SheetSeries {
  std::string label, style;  // style: "line", "points", "errorbar"
  std::vector<double> x, y, lo, hi;
};
struct SheetPlot {
  std::string id, title, x_label, y_label;
  bool log_x = false, log_y = false;
  std::vector<SheetSeries> series;
};

// The data sheet as JSON: {"title", "sections": [section...]}, each section
//   {"id", "title", "standard", "figures": [{"name", "value", "lo", "hi",
//    "sigma", "unit", "note"}], "tables": [{"title", "columns", "rows"}],
//    "plots": [{"id", "title", "x_label", "y_label", "log_x", "log_y",
//    "series": [{"label", "style", "x", "y", "lo", "hi"}]}]}
// which tools/characterize/datasheet.py renders to summary.txt and report.html.
// Values are in the units named beside them (degrees and hours at the edge).
class DataSheet {
 public:
  explicit DataSheet(std::string_view title);

  // IEEE 952: the Allan deviation (deg/h) with its interval, and ARW, bias
  // instability and rate random walk with theirs.
  void noise(std::span<const AllanPoint> curve_rad_s, const NoiseTerms& terms, double confidence);
  // IEEE 1431 scale-factor series and the 4 theta readout error over whole turns.
  void scale_factor(std::span<const RateStep> steps, const ScaleFactorSeries& sf,
                    std::span<const double> true_angle_rad, std::span<const double> readout_rad,
                    const AngleDependentScaleFactor& adsf);
  // IEEE 1431 drift-rate series: turn-on biases (deg/h) and bias against temperature.
  void drift(std::span<const double> turn_on_bias_dph, const Repeatability& rep,
             std::span<const double> temperature_degc, std::span<const double> bias_dph,
             const TemperatureSlope& temp);
  // Rate threshold raw and compensated (deg/h) and the run-down time (s).
  struct Limits {
    double threshold_raw_dph = 0.0, threshold_compensated_dph = 0.0;
    double rundown_s = 0.0;
    std::string note;  // where the figures come from (closed form, measured)
  };
  void limits(const Limits& l);
  // A section assembled by the caller.
  void section(std::string_view id, std::string_view title, std::string_view standard,
               std::span<const SheetFigure> figures, std::span<const SheetTable> tables,
               std::span<const SheetPlot> plots);

  // The whole document; the writer is closed by this call.
  std::string finish();

 private:
  void begin_section(std::string_view id, std::string_view title, std::string_view standard);
  void figure(std::string_view name, double value, double lo, double hi, double sigma,
              std::string_view unit, std::string_view note);

  sim_run::JsonWriter w_;
};

}  // namespace hrg::characterize
