// SPDX-License-Identifier: MIT
// The ring-up's frequency noise. An excitation segment's frequency is read
// from its end rows, whose phase noise is noise / a_A at their own
// amplitude. The firmware's ring-up from rest starts its quiet part at
// a_A ~ 0.1 V and ends it at 0.95 V, but its sigma was taken at the
// segment's mean a_A^2: 1.08e-6 rad/s where its end rows give 3.94e-6
// (seed 5). Over 40 clean 365 s runs (seeds 1-10, 4.2 / 5 / 6 kHz) its
// residual stood 4.4 sigma rms from the free decays (9.5 at most), and as
// the only segment with pump_v^2 100 V^2 and a low a_A^2 it was read as an
// electrostatic spring (1.31e-8 Hz/V^2 at delta BIC 33, seed 5) or a
// Duffing term (1.59e-6 Hz/V^2 at 31.1, seed 9; -1.42e-6 at 21.5 at 4.2
// kHz, seed 7) that a calibration would have carried into the gyro.
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "audit/audit.hpp"
#include "sim_run/report.hpp"
#include "sim_run/run.hpp"
#include "sim_run/scenario_run.hpp"

#include "support/default_scenario.hpp"
#include "support/cpputest.hpp"

TEST_GROUP_WITHOUT_LEAK_CHECK(AuditRingUpNoise);

namespace {

using hrg::audit::AuditResult;
using hrg::audit::Effect;

constexpr double kSeedHz = 5000.0;

// 365 s of the default scenario with noise seed `seed` at resonance `f_hz`
// (the pump gain scaled by (f / 5 kHz)^2: the parametric threshold, 8 w nu /
// k_pump with nu = pi f / Q, stays at the file's 3 V) and an electrostatic
// spring of `spring_hz_per_v2` (0: none), audited.
AuditResult audit_run(unsigned seed, double f_hz, double spring_hz_per_v2 = 0.0) {
  hrg::sim_run::RunConfig j = hrg::test::default_scenario_run();
  j.sim.seed = seed;
  j.sim.resonator.f_hz = f_hz;
  j.sim.electrodes.pump_gain_per_s2_v2 *= (f_hz / kSeedHz) * (f_hz / kSeedHz);
  j.sim.effects.electrostatic_spring = {spring_hz_per_v2 != 0.0, spring_hz_per_v2};
  hrg::sim_run::adopt_resonator(j, "ring-up noise run");
  const auto r = hrg::sim_run::run_simulation(j, {});
  return hrg::audit::run_audit(hrg::sim_run::telemetry_recording(j, r));
}

const hrg::audit::CandidateScore& candidate(const AuditResult& a, Effect e) {
  for (const auto& c : a.candidates)
    if (c.effect == e) return c;
  throw std::runtime_error("the audit scored no candidate of this effect");
}

}  // namespace

TEST(AuditRingUpNoise, TheCleanGyroAtOtherNoiseSeedsAuditsWithNoFinding) {
  // GIVEN the clean gyro (no effect on) at the three seeds and resonances
  // where the ring-up was read as a spring or a Duffing term
  struct Case {
    unsigned seed;
    double f_hz;
  };
  for (const Case c : {Case{5, 5000.0}, Case{9, 5000.0}, Case{7, 4200.0}}) {
    const AuditResult a = audit_run(c.seed, c.f_hz);
    const auto& spring = candidate(a, Effect::electrostatic_spring);
    const auto& duffing = candidate(a, Effect::duffing_stiffness);
    std::printf("\n  seed %u, %.0f Hz: %s, %zu findings; spring %.3g +- %.2g, Duffing %.3g +- %.2g",
                c.seed, c.f_hz, a.verdict.c_str(), a.findings.size(), spring.value, spring.sigma,
                duffing.value, duffing.sigma);
    // THEN nothing is found
    STRCMP_EQUAL("consistent", a.verdict.c_str());
    CHECK(a.findings.empty());
    // AND the ring-up's offset is within its noise: the spring's and the
    // Duffing term's candidates within 3 sigma of zero (6.5 and 6.4 sigma
    // before at seed 5, 6.0 and 6.4 at seed 9)
    CHECK(std::abs(spring.value) < 3.0 * spring.sigma);
    CHECK(std::abs(duffing.value) < 3.0 * duffing.sigma);
  }
  std::printf("\n");
}

TEST(AuditRingUpNoise, ASpringAtTwiceItsThresholdIsStillFoundWithinItsSigma) {
  for (const unsigned seed : {5u, 9u}) {
    // GIVEN the clean run's threshold of the spring (5 of its sigma;
    // 3.2e-8 and 3.9e-8 Hz/V^2), and the same run with a spring of twice it
    const double threshold =
        candidate(audit_run(seed, kSeedHz), Effect::electrostatic_spring).threshold;
    const double truth = 2.0 * threshold;
    const AuditResult a = audit_run(seed, kSeedHz, truth);
    std::printf("\n  seed %u: spring %.4g Hz/V^2 (2x threshold) -> %s", seed, truth,
                a.verdict.c_str());
    // THEN it is the finding, within 3 of its own sigma (before: 7.76e-8 +-
    // 2e-9 for 6.45e-8 at seed 5 and 5.26e-8 +- 2e-9 at seed 9, 6 sigma off)
    CHECK(threshold > 0.0);
    CHECK_EQUAL(1u, a.findings.size());
    CHECK(a.findings.front().effect == Effect::electrostatic_spring);
    const double v = a.findings.front().value, s = a.findings.front().sigma;
    std::printf(": %.4g +- %.2g", v, s);
    CHECK(std::abs(v - truth) < 3.0 * s);
    CHECK(std::abs(v - truth) < 0.25 * truth);
  }
  std::printf("\n");
}
