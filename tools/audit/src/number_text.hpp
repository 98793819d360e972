// SPDX-License-Identifier: MIT
#pragma once

// printf of up to three numbers into a string: the words of the audit's
// locations (selection.cpp) and of its switching-edge debug lines
// (feedthrough_edges.cpp). Private to tools/audit/src.

#include <cstdio>
#include <string>

namespace hrg::audit::detail {

inline std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

}  // namespace hrg::audit::detail
