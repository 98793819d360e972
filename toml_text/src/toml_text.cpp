// SPDX-License-Identifier: MIT
#include "toml_text/toml_text.hpp"

#include <cstdio>
#include <sstream>

namespace hrg::toml_text {

namespace {

void require_ascii(std::string_view text, const std::string& source, std::string_view rule) {
  std::size_t line = 1, column = 1;
  for (const char ch : text) {
    const auto byte = static_cast<unsigned char>(ch);
    if (byte >= 0x80) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", byte);
      throw TextError(source + ":" + std::to_string(line) + ":" + std::to_string(column) +
                      ": non-ASCII byte " + hex + ": " + std::string(rule));
    }
    if (ch == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
}

}  // namespace

toml::table parse(std::string_view text, const std::string& source, std::string_view ascii_rule) {
  require_ascii(text, source, ascii_rule);
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << source << ":" << e.source().begin.line << ":" << e.source().begin.column << ": "
        << e.description();
    throw TextError(msg.str());
  }
}

}  // namespace hrg::toml_text
