// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary text through the DBC parser; it either parses or
// throws DbcError, and every parsed signal fits in 8 bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "can/dbc.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  try {
    const auto dbc = hrg::can::parse_dbc(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.dbc");
    hrg::hal::CanFrame f;
    for (const auto& m : dbc.messages) {
      for (const auto& s : m.signals) {
        if (s.start_bit + s.length > 64) std::abort();
        (void)s.decode(f);
      }
    }
  } catch (const hrg::can::DbcError&) {
  }
  return 0;
}
