// SPDX-License-Identifier: MIT
// The ring electrode's gap harmonics, seen only on the excitation segments
// (the pump's amplitude balance and pattern-angle drift), in both directions:
// slow coloured noise on the demodulated signals, which moves neighbouring
// segments alike, is not read as a gap; and a gap beside a thermal damping,
// which acts on the resonator and which the segments' model holds, is a
// finding although the damping owns nearly all of the free decays' misfit
// (tools/audit/README.md, "A finding must carry its own weight"). Slow: an
// audit of the firmware's telemetry and one of the averaged model's.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "audit/audit.hpp"
#include "../../tools/audit/src/campaign.hpp"
#include "audit_bench_design.hpp"

#include "support/cpputest.hpp"

namespace bench = hrg::audit::bench;
using hrg::audit::AuditResult;
using hrg::audit::Effect;

namespace {

const hrg::audit::Finding* finding_of(const AuditResult& r, Effect e) {
  const auto it = std::find_if(r.findings.begin(), r.findings.end(),
                               [&](const hrg::audit::Finding& f) { return f.effect == e; });
  return it == r.findings.end() ? nullptr : &*it;
}

}  // namespace

TEST_GROUP(AuditGapAcceptance){};

TEST(AuditGapAcceptance, AGapBesideAStrongThermalDampingIsAFinding) {
  // GIVEN `hrg audit-bench --emit OUT --design telemetry --seed 2 --effect
  // thermal_damping 0.03 --effect gap_harmonics 0.006`: a thermal damping
  // that leaves 98 % of the baseline's misfit, on the free decays, and a gap
  // that acts on the excitation segments alone
  bench::Scenario s = bench::random_scenario(bench::Design::telemetry, 480.0, 2);
  CHECK(bench::conceal_by_id(s, "thermal_damping", 0.03, 2));
  CHECK(bench::conceal_by_id(s, "gap_harmonics", 0.006, 2));
  s.temp_cycles = true;
  // WHEN it is audited
  const AuditResult r = hrg::audit::run_audit(bench::simulate(s));
  const std::string text = hrg::audit::to_text(r, "thermal damping + gap");
  // THEN both are findings: the gap within 20 % of 0.006 and 2 of its
  // sigmas (before: an alternative, 0.006921 at delta BIC 14.3 "removes less
  // than its share of the misfit", weighed against the damping's), the
  // thermal damping within 5 %
  const auto* gap = finding_of(r, Effect::gap_harmonics);
  const auto* td = finding_of(r, Effect::thermal_damping);
  CHECK_TEXT(gap != nullptr && td != nullptr, text.c_str());
  CHECK_TEXT(std::abs(gap->value - 0.006) <= 0.2 * 0.006, text.c_str());
  CHECK_TEXT(std::abs(gap->value - 0.006) <= 2.0 * gap->sigma, text.c_str());
  CHECK_TEXT(gap->significance >= 5.0, text.c_str());
  CHECK_TEXT(std::abs(td->value - 0.03) <= 0.05 * 0.03, text.c_str());
}

TEST(AuditGapAcceptance, AGapAtTwiceItsThresholdBesideColouredNoiseIsFound) {
  // GIVEN `hrg audit-bench --emit OUT --design telemetry --seed 3 --flicker
  // 1.5 --effect gap_harmonics 0.0043`: a gap at twice the threshold of the
  // white null of the same campaign (0.00215) and 1/f noise on every
  // demodulated signal, its offsets and drifts among it
  bench::Scenario s = bench::random_scenario(bench::Design::telemetry, 480.0, 3);
  CHECK(bench::conceal_by_id(s, "gap_harmonics", 0.0043, 3));
  s.flicker_corner_hz = 1.5;
  s.temp_cycles = true;
  // WHEN it is audited
  const AuditResult r = hrg::audit::run_audit(bench::simulate(s));
  const std::string text = hrg::audit::to_text(r, "gap 2x threshold beside 1/f noise");
  // THEN the gap is a finding within 20 % and 5 of its sigmas stand from
  // zero: what a slow offset of the demodulated signals explains of the
  // segments' observations is not the gap's 4-theta pattern (0.004125 +-
  // 0.00052, 7.9 sigma)
  const auto* gap = finding_of(r, Effect::gap_harmonics);
  CHECK_TEXT(gap != nullptr, text.c_str());
  CHECK_TEXT(std::abs(gap->value - 0.0043) <= 0.2 * 0.0043, text.c_str());
  CHECK_TEXT(gap->significance >= 5.0, text.c_str());
}

// The firmware's simulated target keeps process-wide state (its singleton
// and buffers) that outlives the test.
TEST_GROUP_WITHOUT_LEAK_CHECK(AuditGapAcceptanceFirmware);

TEST(AuditGapAcceptanceFirmware, ColouredNullIsNoGap) {
  // GIVEN the 1/f null of design 8 of `hrg audit-bench --seed 2026` (the
  // firmware's own telemetry, its reference fixed 0.69 Hz off the
  // resonance): nothing concealed, 1/f noise on every demodulated signal at
  // the corner the benchmark draws (0.93 Hz). Its slowest octaves, offsets
  // that beat with the vibration's phase turning in the demodulation frame,
  // move the end rows of neighbouring excitation segments alike (lag-1
  // correlation 0.47 of the noise's part of their amplitude balance)
  bench::Scenario s = bench::test::firmware_design(2026, 8);
  std::mt19937_64 g((2026ULL * 100003ULL + 8) ^ 0x5bd1e9955bd1e995ULL);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  s.flicker_corner_hz = std::exp(std::log(0.3) + u(g) * std::log(10.0));
  DOUBLES_EQUAL(0.93, s.flicker_corner_hz, 0.005);
  // WHEN it is audited
  const AuditResult r = hrg::audit::run_audit(bench::simulate(s));
  const std::string text = hrg::audit::to_text(r, "1/f null, design 8");
  // THEN there is no finding (before: a gap harmonic of |eps| 0.0181 +-
  // 0.0034 at delta BIC 11.9, its evidence the balance's slow pattern)
  CHECK_TEXT(r.findings.empty(), text.c_str());
}

TEST(AuditGapAcceptanceFirmware, AColouredNullWhosePatternAnOffsetExplainsIsNoGap) {
  // GIVEN `hrg audit-bench --emit OUT --design firmware --seed 25 --flicker
  // 1.5`: nothing concealed, 1/f noise on every demodulated signal (corner
  // 1.5 Hz). Its slowest octaves are offsets and drifts of cx, sx, cy, sy
  // over the recording; read at the end rows of segments a free window
  // apart, they beat with the vibration's phase (the reference 0.97 Hz off the
  // resonance) and with the pattern angle into a 4-theta pattern of the
  // amplitude balance and the angle drift that repeats over both turns of
  // the pattern (its two halves agree on it)
  bench::Scenario s = bench::random_scenario(bench::Design::firmware, 480.0, 25);
  s.flicker_corner_hz = 1.5;
  s.temp_cycles = true;
  // WHEN it is audited
  const AuditResult r = hrg::audit::run_audit(bench::simulate(s));
  const std::string text = hrg::audit::to_text(r, "1/f null, firmware seed 25");
  // THEN there is no finding (before: a gap harmonic of |eps| 0.0171 +-
  // 0.0031 at delta BIC 21.8 and 5.5 sigma, "removes 290 % of the
  // baseline's misfit beyond the noise"; an offset and a drift of the four
  // signals explain 20.2 of the 36.7 its drop-one refit removes)
  CHECK_TEXT(r.findings.empty(), text.c_str());
}
