// SPDX-License-Identifier: MIT
#pragma once
// Designs of `hrg audit-bench --seed S` rebuilt as the bench builds them
// (tools/audit/src/bench.cpp, run_design): seed S * 100003 + d, a reference
// that follows the resonance (the telemetry designs with (d / 3) odd), and a
// temperature that does not follow time. Include before support/cpputest.hpp.
#include <cstdint>

#include "../../tools/audit/src/campaign.hpp"

namespace hrg::audit::bench::test {

inline Scenario pll_telemetry_design(uint64_t bench_seed, uint64_t design, double duration_s) {
  Scenario s = random_scenario(Design::telemetry, duration_s, bench_seed * 100003ULL + design);
  s.pll_reference = true;
  s.temp_cycles = true;
  return s;
}

// A telemetry design whose reference is fixed ((d / 3) even).
inline Scenario telemetry_design(uint64_t bench_seed, uint64_t design, double duration_s) {
  Scenario s = random_scenario(Design::telemetry, duration_s, bench_seed * 100003ULL + design);
  s.temp_cycles = true;
  return s;
}

// A firmware design (d % 3 == 2) as the bench builds it: the firmware's own
// telemetry, its reference fixed, a temperature that does not follow time.
inline Scenario firmware_design(uint64_t bench_seed, uint64_t design) {
  Scenario s = random_scenario(Design::firmware, 360.0, bench_seed * 100003ULL + design);
  s.temp_cycles = true;
  return s;
}

}  // namespace hrg::audit::bench::test
