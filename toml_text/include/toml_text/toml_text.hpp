// SPDX-License-Identifier: MIT
#pragma once

// The one way our TOML readers include and call toml++ 3.3.0 (Debian 12):
// - it asserts a precondition in parse_key that a malformed table header
//   ('[[[1]]]', '[\v]') breaks (upstream marzer/tomlplusplus#301); without
//   the assertion it reports the parse error, which a user of any build
//   (Release, sanitizers, fuzzing) must get: its assertions are off here, for
//   every file that includes toml++ through this header;
// - it reaches __builtin_unreachable on some non-ASCII code points where it
//   looks for whitespace (upstream #295, found by our fuzzer): undefined
//   behaviour, not an error. Our files are ASCII, so a non-ASCII byte is
//   refused before toml++ sees the text.
#ifndef TOML_ASSERT
#define TOML_ASSERT(expr) static_cast<void>(0)
#endif
#include <toml++/toml.h>

#include <stdexcept>
#include <string>
#include <string_view>

namespace hrg::toml_text {

// What parse() refuses; what() names the file, line and column.
class TextError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses `text` (`source` names it in messages). Throws TextError with
//   "<source>:<line>:<column>: non-ASCII byte 0x<hex>: <ascii_rule>"
// at the first byte >= 0x80, or
//   "<source>:<line>:<column>: <toml++'s description>"
// for a TOML syntax error.
toml::table parse(std::string_view text, const std::string& source, std::string_view ascii_rule);

}  // namespace hrg::toml_text
