// SPDX-License-Identifier: MIT
#include "sim_run/json.hpp"

#include <cmath>
#include <cstdio>

namespace hrg::sim_run {

std::string JsonWriter::escape(std::string_view s) {
  std::string r;
  for (char c : s) {
    switch (c) {
      case '"': r += "\\\""; break;
      case '\\': r += "\\\\"; break;
      case '\n': r += "\\n"; break;
      case '\t': r += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          r += buf;
        } else {
          r += c;
        }
    }
  }
  return r;
}

void JsonWriter::prefix(std::string_view key) {
  if (!first_) out_ += ",";
  if (depth_ > 0) {
    out_ += "\n";
    out_.append(static_cast<std::size_t>(depth_) * 2, ' ');
  }
  if (!key.empty()) {
    out_ += '"';
    out_ += escape(key);
    out_ += "\": ";
  }
  first_ = false;
}

void JsonWriter::begin_object(std::string_view key) {
  prefix(key);
  out_ += "{";
  ++depth_;
  first_ = true;
}

void JsonWriter::end_object() {
  --depth_;
  out_ += "\n";
  out_.append(static_cast<std::size_t>(depth_) * 2, ' ');
  out_ += "}";
  first_ = false;
  if (depth_ == 0) out_ += "\n";
}

void JsonWriter::begin_array(std::string_view key) {
  prefix(key);
  out_ += "[";
  ++depth_;
  first_ = true;
}

void JsonWriter::end_array() {
  --depth_;
  out_ += "]";
  first_ = false;
}

void JsonWriter::number(std::string_view key, double v) {
  prefix(key);
  if (!std::isfinite(v)) {
    out_ += "null";
    return;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  out_ += buf;
}

void JsonWriter::integer(std::string_view key, long long v) {
  prefix(key);
  out_ += std::to_string(v);
}

void JsonWriter::string(std::string_view key, std::string_view v) {
  prefix(key);
  out_ += '"';
  out_ += escape(v);
  out_ += '"';
}

void JsonWriter::boolean(std::string_view key, bool v) {
  prefix(key);
  out_ += v ? "true" : "false";
}

}  // namespace hrg::sim_run
