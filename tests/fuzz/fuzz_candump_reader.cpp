// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary text through the candump -l log reader. Every
// line either parses or throws CandumpError; a parsed data frame formats back
// to a line that parses to the same frame.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "can/candump_log.hpp"

using namespace hrg::can;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  CandumpLogReader reader(in);
  LoggedFrame lf;
  for (;;) {
    try {
      if (!reader.next(lf)) break;
    } catch (const CandumpError& e) {
      if (e.line() == 0) std::abort();
      continue;  // the reader goes on with the next line
    }
    if (lf.error_frame || lf.remote || lf.interface.find(' ') != std::string::npos) continue;
    const std::string line = format_candump_line(lf.frame, lf.t_ns, lf.interface);
    LoggedFrame again;
    std::string err;
    if (!parse_candump_line(line, again, err)) std::abort();
    if (again.frame.id != lf.frame.id || again.frame.extended != lf.frame.extended ||
        again.frame.len != lf.frame.len || again.frame.data != lf.frame.data ||
        again.t_ns / 1000 != lf.t_ns / 1000) {
      std::abort();
    }
  }
  return 0;
}
