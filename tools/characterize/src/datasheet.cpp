// SPDX-License-Identifier: MIT
#include "characterize/datasheet.hpp"

#include "sheet_json.hpp"

namespace hrg::characterize {

DataSheet::DataSheet(std::string_view title) {
  w_.begin_object();
  w_.string("title", title);
  w_.begin_array("sections");
}

void DataSheet::begin_section(std::string_view id, std::string_view title,
                              std::string_view standard) {
  w_.begin_object();
  w_.string("id", id);
  w_.string("title", title);
  w_.string("standard", standard);
}

void DataSheet::figure(std::string_view name, double value, double lo, double hi, double sigma,
                       std::string_view unit, std::string_view note) {
  w_.begin_object();
  w_.string("name", name);
  w_.number("value", value);
  w_.number("lo", lo);
  w_.number("hi", hi);
  w_.number("sigma", sigma);
  w_.string("unit", unit);
  w_.string("note", note);
  w_.end_object();
}

void DataSheet::section(std::string_view id, std::string_view title, std::string_view standard,
                        std::span<const SheetFigure> figures, std::span<const SheetTable> tables,
                        std::span<const SheetPlot> plots) {
  begin_section(id, title, standard);
  w_.begin_array("figures");
  for (const SheetFigure& f : figures)
    figure(f.name, f.value, f.lo, f.hi, f.sigma, f.unit, f.note);
  w_.end_array();
  w_.begin_array("tables");
  for (const SheetTable& t : tables)
    sheet::table(w_, t.title, t.columns, t.rows);
  w_.end_array();
  w_.begin_array("plots");
  for (const SheetPlot& p : plots)
    sheet::plot(w_, p.id, p.title, p.x_label, p.y_label, p.log_x, p.log_y, p.series);
  w_.end_array();
  w_.end_object();
}

std::string DataSheet::finish() {
  w_.end_array();
  w_.end_object();
  return w_.str();
}

}  // namespace hrg::characterize
