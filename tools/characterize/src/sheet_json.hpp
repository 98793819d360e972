// SPDX-License-Identifier: MIT
// JSON pieces of the data sheet: series of a plot, tables, number arrays.
#pragma once

#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include "characterize/datasheet.hpp"
#include "characterize/noise_terms.hpp"
#include "sim_run/json.hpp"

namespace hrg::characterize::sheet {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();  // written as null
constexpr double kDeg = 180.0 / std::numbers::pi;

inline std::string fmt(const char* f, double v) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

inline void numbers(sim_run::JsonWriter& w, std::string_view key, const std::vector<double>& v) {
  w.begin_array(key);
  for (const double x : v)
    w.number(x);
  w.end_array();
}

using Series = SheetSeries;

inline void plot(sim_run::JsonWriter& w, std::string_view id, std::string_view title,
                 std::string_view x_label, std::string_view y_label, bool log_x, bool log_y,
                 const std::vector<Series>& series) {
  w.begin_object();
  w.string("id", id);
  w.string("title", title);
  w.string("x_label", x_label);
  w.string("y_label", y_label);
  w.boolean("log_x", log_x);
  w.boolean("log_y", log_y);
  w.begin_array("series");
  for (const Series& s : series) {
    w.begin_object();
    w.string("label", s.label);
    w.string("style", s.style);
    numbers(w, "x", s.x);
    numbers(w, "y", s.y);
    if (!s.lo.empty()) numbers(w, "lo", s.lo);
    if (!s.hi.empty()) numbers(w, "hi", s.hi);
    w.end_object();
  }
  w.end_array();
  w.end_object();
}

inline void table(sim_run::JsonWriter& w, std::string_view title,
                  const std::vector<std::string>& columns,
                  const std::vector<std::vector<std::string>>& rows) {
  w.begin_object();
  w.string("title", title);
  w.begin_array("columns");
  for (const auto& c : columns)
    w.string({}, c);
  w.end_array();
  w.begin_array("rows");
  for (const auto& r : rows) {
    w.begin_array();
    for (const auto& c : r)
      w.string({}, c);
    w.end_array();
  }
  w.end_array();
  w.end_object();
}

inline std::string resolved(const SlopeReading& r) {
  return r.on_slope ? "" : " NOT on its slope in this record: an upper bound";
}

}  // namespace hrg::characterize::sheet
