// SPDX-License-Identifier: MIT
// A pickoff phase mismatch phi reads a standing vibration's phase at about
// -phi sin^2 2theta, so while the table turns the pattern it moves each
// excitation segment's measured frequency by the change of that readout
// between the segment's ends over t1 - t0. The measured frequency is the
// change of the phase's mean over the three rows at each end, so the
// readout's change must be taken between the same rows: between the single
// end rows it is (q1 - q0) / (q1 - q0 - 2) as large, 2.7 % on the
// firmware's 0.75 s segments at 100 Hz rows. At one table rate that readout
// is a split's shape (dw_S = -2 phi theta'), which the baseline takes up, so
// those 2.7 % read the phase mismatch 23 % low (tools/audit/README.md, step
// 2).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "audit/audit.hpp"
#include "../../tools/audit/src/campaign.hpp"
#include "../../tools/audit/src/dataset.hpp"
#include "../../tools/audit/src/model.hpp"
#include "audit_bench_design.hpp"

#include "support/cpputest.hpp"

namespace bench = hrg::audit::bench;
namespace detail = hrg::audit::detail;
using hrg::audit::AuditResult;
using hrg::audit::Effect;

namespace {

constexpr double kPhaseDeg = 0.5093;  // the benchmark's pair on design 5
constexpr double kDuffingHzPerV2 = 0.0002434;

// Design 5 of `hrg audit-bench --seed 2026`: the firmware's telemetry, 0.75 s
// excitation segments between windows while the table turns at 11 deg/s.
bench::Scenario design_5() { return bench::test::firmware_design(2026, 5); }

detail::Dataset noise_free_dataset(double phase_deg) {
  bench::Scenario s = design_5();
  s.noise_v = 1e-8;
  if (phase_deg != 0.0) CHECK(bench::conceal_by_id(s, "pickoff_phase_mismatch", phase_deg, 1));
  return detail::build_dataset(bench::simulate(s), 12000);
}

}  // namespace

// The firmware's simulated target keeps process-wide state (its singleton
// and buffers) that outlives the test.
TEST_GROUP_WITHOUT_LEAK_CHECK(AuditPhaseReadout);

TEST(AuditPhaseReadout, TheSegmentsFrequencyModelHoldsAPhaseMismatchToAFewTenthsOfAPercent) {
  // GIVEN the design's campaign without noise, with and without the phase
  // mismatch (the same campaign: the difference is the phase's alone)
  const detail::Dataset with = noise_free_dataset(kPhaseDeg);
  const detail::Dataset without = noise_free_dataset(0.0);
  // WHEN each segment's frequency change is set against what the model makes
  // of the phase mismatch there (its readout and the pump's pull; the rest
  // of the model is the same with and without it and cancels)
  detail::Params p{};
  p[detail::kNu] = design_5().resonator.nu_per_s();
  const std::vector<double> r0 = detail::forced_residuals(with, p);
  p[detail::kPhase] = kPhaseDeg * std::numbers::pi / 180.0;
  const std::vector<double> r1 = detail::forced_residuals(with, p);
  // The datasets' carriers (each its median vibration frequency) differ: the
  // frequencies differ by a constant as well, the fit's mean frequency.
  std::vector<double> miss, part;
  for (std::size_t i = 0; i < with.forced.size(); ++i) {
    const auto& f = with.forced[i];
    const auto twin = std::find_if(
        without.forced.begin(), without.forced.end(),
        [&f](const auto& g) { return g.first_row == f.first_row && g.last_row == f.last_row; });
    if (twin == without.forced.end()) continue;
    const double measured = f.freq_rad_s - twin->freq_rad_s;
    const double model = r0[i] - r1[i];
    miss.push_back(measured - model);
    part.push_back(model);
  }
  CHECK_TRUE(miss.size() >= 15);
  const double n = static_cast<double>(miss.size());
  const double offset = std::accumulate(miss.begin(), miss.end(), 0.0) / n;
  double miss2 = 0.0, part2 = 0.0;
  for (std::size_t i = 0; i < miss.size(); ++i)
    miss2 += (miss[i] - offset) * (miss[i] - offset), part2 += part[i] * part[i];
  // THEN the model holds it to 0.5 % rms (measured 0.077 % on 18 segments;
  // the readout between the single end rows missed by 2.4 %, 3e-5 rad/s)
  const double ratio = std::sqrt(miss2 / part2);
  CHECK_TEXT(ratio < 0.005, ("model misses by " + std::to_string(ratio)).c_str());
}

TEST(AuditPhaseReadout, APhaseMismatchBesideADuffingTermIsReadWithinTwoSigma) {
  // GIVEN the benchmark's pair of design 5 with its noise
  bench::Scenario s = design_5();
  CHECK(bench::conceal_by_id(s, "pickoff_phase_mismatch", kPhaseDeg, 1));
  CHECK(bench::conceal_by_id(s, "duffing_stiffness", kDuffingHzPerV2, 1));
  // WHEN it is audited
  const AuditResult r = hrg::audit::run_audit(bench::simulate(s));
  const std::string text = hrg::audit::to_text(r, "pair");
  // THEN the phase mismatch is a finding within 20 % and 2 sigma (before:
  // 0.3952 +- 0.047 deg, 22 % and 2.4 sigma low), the Duffing term within 20 %
  const auto find = [&r](Effect e) {
    return std::find_if(r.findings.begin(), r.findings.end(),
                        [e](const auto& f) { return f.effect == e; });
  };
  const auto phase = find(Effect::pickoff_phase_mismatch);
  CHECK_TEXT(phase != r.findings.end(), text.c_str());
  CHECK_TEXT(std::abs(phase->value - kPhaseDeg) <= 0.2 * kPhaseDeg, text.c_str());
  CHECK_TEXT(std::abs(phase->value - kPhaseDeg) <= 2.0 * phase->sigma, text.c_str());
  const auto duffing = find(Effect::duffing_stiffness);
  CHECK_TEXT(duffing != r.findings.end(), text.c_str());
  CHECK_TEXT(std::abs(duffing->value - kDuffingHzPerV2) <= 0.2 * kDuffingHzPerV2, text.c_str());
}
