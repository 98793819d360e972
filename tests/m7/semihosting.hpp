// SPDX-License-Identifier: MIT
#pragma once

// ARM semihosting (BKPT 0xAB on M-profile), as QEMU implements it with
// -semihosting-config enable=on,target=native.

#include <cstdint>

namespace hrg::m7 {

inline uint32_t semihost_call(uint32_t op, const void* arg) {
  register uint32_t r0 asm("r0") = op;
  register const void* r1 asm("r1") = arg;
  asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

// SYS_WRITE0: a NUL-terminated string to the host's stdout.
inline void semihost_write0(const char* s) { semihost_call(0x04u, s); }

// SYS_EXIT: ADP_Stopped_ApplicationExit makes QEMU exit with status 0, any
// other reason (here ADP_Stopped_RunTimeErrorUnknown) with status 1.
[[noreturn]] inline void semihost_exit(bool success) {
  const uint32_t reason = success ? 0x20026u : 0x20023u;
  semihost_call(0x18u, reinterpret_cast<const void*>(reason));
  for (;;) {
  }
}

}  // namespace hrg::m7
