// SPDX-License-Identifier: MIT
#include "report.hpp"

namespace hrg::m7 {

void Report::number(int64_t v) {
  char buf[24];
  int n = 0;
  uint64_t u = v < 0 ? static_cast<uint64_t>(-(v + 1)) + 1u : static_cast<uint64_t>(v);
  do {
    buf[n++] = static_cast<char>('0' + u % 10u);
    u /= 10u;
  } while (u != 0u);
  char out[26];
  int k = 0;
  if (v < 0) out[k++] = '-';
  while (n > 0)
    out[k++] = buf[--n];
  out[k] = '\0';
  write_text(out);
}

void Report::hex64(uint64_t v) {
  char out[17];
  for (int i = 0; i < 16; ++i) {
    const auto nib = static_cast<unsigned>((v >> (60 - 4 * i)) & 0xFu);
    out[i] = static_cast<char>(nib < 10u ? '0' + nib : 'a' + nib - 10u);
  }
  out[16] = '\0';
  write_text(out);
}

void Report::figure(const char* name, int64_t v) {
  write_text(name);
  write_text(": ");
  number(v);
  write_text("\n");
}

void Report::check(bool ok, const char* what) {
  ++checks_;
  if (!ok) {
    ++failures_;
    write_text("FAIL: ");
    write_text(what);
    write_text("\n");
  }
}

}  // namespace hrg::m7
