// SPDX-License-Identifier: MIT
// Host runner of the fixed-point suite: same code and digest as on the M7.
#include <cstdio>

#include "report.hpp"

namespace hrg::m7 {
void write_text(const char* s) { std::fputs(s, stdout); }
}  // namespace hrg::m7

int main() {
  hrg::m7::Report r;
  return hrg::m7::run_fixed_suite(r) == 0 ? 0 : 1;
}
