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

std::string DataSheet::finish() {
  w_.end_array();
  w_.end_object();
  return w_.str();
}

}  // namespace hrg::characterize
