// SPDX-License-Identifier: MIT
// A single catalogue effect at 2.5x its detection threshold on the averaged
// model's telemetry is a finding, although that design's excitation segments
// keep a pull no catalogue term holds (their pattern drift at about 5.7x its
// noise, the null included): the effect is weighed against the misfit where
// its evidence lies (tools/audit/README.md step 7). Slow: three audits.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "audit/audit.hpp"
#include "../../tools/audit/src/campaign.hpp"
#include "audit_bench_design.hpp"

#include "support/cpputest.hpp"

namespace bench = hrg::audit::bench;
using hrg::audit::AuditResult;
using hrg::audit::Effect;

namespace {

// Design 10 of `hrg audit-bench --seed 2026` (seed 2026 * 100003 + 10): a
// telemetry campaign of 360 s against a reference that follows the resonance.
bench::Scenario telemetry() { return bench::test::pll_telemetry_design(2026, 10, 360.0); }

double threshold_of(const AuditResult& r, Effect e) {
  for (const auto& c : r.candidates) {
    if (c.effect == e && c.testable) return c.threshold;
  }
  return 0.0;
}

// The effect concealed at `strength` x the threshold the null twin's audit
// gives, audited; checks it is the finding and within 20 % of the truth.
void check_found_at(Effect e, const AuditResult& null_r, double strength) {
  const double th = threshold_of(null_r, e);
  CHECK(th > 0.0);
  const double truth = strength * th;
  bench::Scenario s = telemetry();
  CHECK(bench::conceal_by_id(s, hrg::audit::effect_info(e).id, truth, 1));
  const AuditResult r = hrg::audit::run_audit(bench::simulate(s));
  const std::string text = hrg::audit::to_text(r, hrg::audit::effect_info(e).id);
  STRCMP_EQUAL_TEXT("explained", r.verdict.c_str(), text.c_str());
  CHECK_TEXT(!r.findings.empty(), text.c_str());
  CHECK_TEXT(r.findings.front().effect == e, text.c_str());
  CHECK_TEXT(std::abs(r.findings.front().value - truth) <= 0.2 * std::abs(truth), text.c_str());
  // The share it explains is of the misfit where its evidence lies (the
  // free decays), not of the excitation segments' pull.
  CHECK_TEXT(r.findings.front().explains_fraction >= 0.2, text.c_str());
}

}  // namespace

TEST_GROUP(AuditWeakEffect){};

TEST(AuditWeakEffect, FreeDecayEffectsBesideTheExcitationPullAreFound) {
  // GIVEN the null twin: consistent, and the thresholds it gives
  const AuditResult null_r = hrg::audit::run_audit(bench::simulate(telemetry()));
  STRCMP_EQUAL_TEXT("consistent", null_r.verdict.c_str(),
                    hrg::audit::to_text(null_r, "null").c_str());
  // WHEN a pickoff gain mismatch, then a misalignment, is concealed at 2.5x
  // THEN each is the finding, within 20 % (main before this: `consistent`,
  // the gain an alternative removing 12 % of a misfit mostly the pull's)
  check_found_at(Effect::pickoff_gain_mismatch, null_r, 2.5);
  check_found_at(Effect::pickoff_misalignment, null_r, 2.5);
}
