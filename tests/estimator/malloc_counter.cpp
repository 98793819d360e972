// SPDX-License-Identifier: MIT
#include "malloc_counter.hpp"

#include <cstddef>

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define HRG_MALLOC_COUNTER 1
#else
#define HRG_MALLOC_COUNTER 0
#endif

namespace {
volatile bool g_armed = false;
volatile long g_count = 0;
}  // namespace

#if HRG_MALLOC_COUNTER
extern "C" {
void* __libc_malloc(std::size_t n);
void* __libc_realloc(void* p, std::size_t n);
void* __libc_calloc(std::size_t a, std::size_t b);

void* malloc(std::size_t n) {
  if (g_armed) g_count = g_count + 1;
  return __libc_malloc(n);
}
void* realloc(void* p, std::size_t n) {
  if (g_armed) g_count = g_count + 1;
  return __libc_realloc(p, n);
}
void* calloc(std::size_t a, std::size_t b) {
  if (g_armed) g_count = g_count + 1;
  return __libc_calloc(a, b);
}
}
#endif

namespace hrg::est::test {

bool malloc_counter_available() { return HRG_MALLOC_COUNTER != 0; }

void malloc_counter_arm() {
  g_count = 0;
  g_armed = true;
}

long malloc_counter_disarm() {
  g_armed = false;
  return g_count;
}

}  // namespace hrg::est::test
