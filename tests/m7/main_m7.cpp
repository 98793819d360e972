// SPDX-License-Identifier: MIT
// Cortex-M7 runner of the fixed-point suite (output through semihosting).
#include "report.hpp"
#include "semihosting.hpp"

namespace hrg::m7 {
void write_text(const char* s) { semihost_write0(s); }
}  // namespace hrg::m7

int main() {
  hrg::m7::Report r;
  return hrg::m7::run_fixed_suite(r) == 0 ? 0 : 1;
}
