// SPDX-License-Identifier: MIT
#pragma once

// Counts heap allocations made through malloc/realloc/calloc while armed, so
// the no-allocation check works in Release too (Eigen's
// set_is_malloc_allowed(false) only asserts when NDEBUG is not defined).
// Available on glibc without AddressSanitizer (which owns malloc); elsewhere
// available() is false and the tests fall back to Eigen's guard alone.

namespace hrg::est::test {

bool malloc_counter_available();
void malloc_counter_arm();
// Disarms and returns the number of allocations since arming.
long malloc_counter_disarm();

}  // namespace hrg::est::test
