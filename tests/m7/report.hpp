// SPDX-License-Identifier: MIT
#pragma once

// Minimal reporting for the fixed-point suite, the same on the host (stdio)
// and on bare metal (semihosting): text lines, integer figures and a 64-bit
// FNV-1a digest of every Q1.31 word the suite produces. No heap, no stdio on
// the target.

#include <cstddef>
#include <cstdint>

namespace hrg::m7 {

// Platform output: one NUL-terminated string (semihosting SYS_WRITE0 or fputs).
void write_text(const char* s);

class Report {
 public:
  void text(const char* s) { write_text(s); }
  void number(int64_t v);
  void hex64(uint64_t v);
  // "name: value\n"
  void figure(const char* name, int64_t v);
  void check(bool ok, const char* what);
  void digest_word(int32_t v) {
    const auto u = static_cast<uint32_t>(v);
    for (int b = 0; b < 4; ++b) {
      digest_ ^= (u >> (8 * b)) & 0xFFu;
      digest_ *= 0x100000001B3ull;
    }
  }
  uint64_t digest() const { return digest_; }
  int failures() const { return failures_; }
  int checks() const { return checks_; }

 private:
  uint64_t digest_ = 0xCBF29CE484222325ull;
  int failures_ = 0;
  int checks_ = 0;
};

// The suite itself; returns the number of failed checks.
int run_fixed_suite(Report& r);

}  // namespace hrg::m7
