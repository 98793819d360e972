// SPDX-License-Identifier: MIT
// A small run of the audit benchmark with its rates asserted (slow).
#include <cstdio>

#include "audit/bench.hpp"

#include "support/cpputest.hpp"

TEST_GROUP(AuditBenchmark){};

TEST(AuditBenchmark, ConcealedEffectsAreFoundAndNullsStayClean) {
  hrg::audit::BenchOptions o;
  o.designs = 2;
  o.seed = 3;
  o.ringdown_s = 300.0;
  o.telemetry_s = 240.0;
  const auto r = hrg::audit::run_benchmark(o);
  std::printf("\n%s", hrg::audit::format_benchmark(r).c_str());
  // Every design gives a null; no null may produce a finding.
  LONGS_EQUAL(2, r.nulls);
  LONGS_EQUAL(0, r.null_findings);
  // Above 2x threshold the concealed effect is the top finding with its
  // parameter within 20 %: at least 4 of 5 in this small sample.
  CHECK(r.above2x >= 3);
  CHECK(5 * r.above2x_hits >= 4 * r.above2x);
}
