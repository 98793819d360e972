// SPDX-License-Identifier: MIT
// Drive feedthrough on a 1-hour telemetry recording (the firmware's interval
// shutdown: hundreds of switch-offs). The sign-free statistic averages the
// squared jump over every switch-off, so a bias of a fraction of the noise per
// edge adds up: a null must stay a null, and a feedthrough at twice its
// detection threshold must still be found with its value (slow: two 1-hour
// simulations and audits).
#include <cmath>
#include <string>

#include "audit/audit.hpp"
#include "audit/bench.hpp"
#include "../../tools/audit/src/campaign.hpp"
#include "recording/recording.hpp"

#include "support/cpputest.hpp"

using hrg::audit::AuditResult;
using hrg::audit::Effect;

namespace {

// The campaign of `hrg audit-bench --seed 99`'s speed run.
hrg::audit::bench::Scenario hour_of_telemetry() {
  return hrg::audit::bench::random_scenario(hrg::audit::bench::Design::telemetry, 3600.0, 99);
}

}  // namespace

TEST_GROUP(AuditFeedthrough){};

TEST(AuditFeedthrough,
     AnHourOfSwitchOffsWithoutFeedthroughIsANullAndAFeedthroughAtTwiceItsThresholdIsFound) {
  auto s = hour_of_telemetry();
  // GIVEN an hour of telemetry with nothing concealed
  const AuditResult null = hrg::audit::run_audit(hrg::audit::bench::simulate(s));
  // THEN no feedthrough is claimed: the jump along the force-driven slope is
  // removed with a slope measured on rows whose noise is not the jump's.
  STRCMP_EQUAL("consistent", null.verdict.c_str());
  LONGS_EQUAL(0, null.findings.size());
  double threshold = 0.0, value = 0.0, sigma = 0.0;
  for (const auto& c : null.candidates) {
    if (c.effect == Effect::drive_feedthrough) {
      threshold = c.threshold, value = c.value, sigma = c.sigma;
    }
  }
  CHECK(threshold > 0.0);
  // The fitted feedthrough of the null is noise: within 3 sigma of zero.
  CHECK(std::abs(value) < 3.0 * sigma);

  // GIVEN the same campaign whose pump couples into the pickoffs at 2x the
  // threshold (the jump c V at every switching instant, V the pump voltage)
  const double c_v_per_v = 2.0 * threshold;
  CHECK(hrg::audit::bench::conceal_by_id(s, "drive_feedthrough", c_v_per_v, 99));
  const AuditResult r = hrg::audit::run_audit(hrg::audit::bench::simulate(s));
  // THEN it is the top finding with its value within 20 %
  CHECK(!r.findings.empty());
  CHECK(r.findings.front().effect == Effect::drive_feedthrough);
  DOUBLES_EQUAL(c_v_per_v, r.findings.front().value, 0.2 * c_v_per_v);
}
