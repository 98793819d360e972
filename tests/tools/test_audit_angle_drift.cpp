// SPDX-License-Identifier: MIT
// The excitation segments' pattern-angle drift on a null telemetry recording:
// the generator's segments neither steer the pattern nor change the rate
// within a segment, so the pattern precesses freely, theta' = (D - K Omega)/2
// with D the damping anisotropy's drift nu dmu sin 4(theta - th_mu)
// (physics.md section 2). Read over the time between the single rows its end
// angles are taken at, the drift sits at the white noise of those angles;
// over the three-row means' span (two rows shorter) it misses by 2 dt / T of
// K Omega / 2, far above that noise; the audit's own angle residuals
// (model.hpp) read it over the end rows' span.
#include <cmath>
#include <string>
#include <vector>

#include "../../tools/audit/src/campaign.hpp"
#include "../../tools/audit/src/dataset.hpp"
#include "../../tools/audit/src/model.hpp"
#include "audit_bench_design.hpp"
#include "recording/recording.hpp"

#include "support/cpputest.hpp"

namespace bench = hrg::audit::bench;
namespace detail = hrg::audit::detail;

namespace {

// The telemetry design of `hrg audit-bench --seed 2026` (design 1): 360 s of
// 4-10 s excitation segments at 200 Hz, rate steps of up to 30 deg/s.
constexpr uint64_t kSeed = 2026ULL * 100003ULL + 1ULL;

// The free precession of the true resonator over segment f, rad/s.
double free_drift_rad_s(const bench::Scenario& s, const detail::ForcedSegment& f) {
  const auto& r = s.resonator;
  const double dnu_c = r.nu_per_s() * r.dmu * std::cos(4.0 * r.th_mu_rad);
  const double dnu_s = r.nu_per_s() * r.dmu * std::sin(4.0 * r.th_mu_rad);
  const double d = dnu_c * f.mean_s4 - dnu_s * f.mean_c4;
  return 0.5 * (d - r.angular_gain * f.mean_rate_rad_s);
}

// Sum over the segments of ((theta1 - theta0) / span - free drift)^2 over the
// white-noise error of the two single-row end angles.
template <typename Span>
double chi2(const bench::Scenario& s, const detail::Dataset& d, Span span_s) {
  double c = 0.0;
  for (const auto& f : d.forced) {
    const double se = std::sqrt(2.0) * d.noise_v / (2.0 * std::sqrt(f.mean_a2)) / span_s(f);
    const double z = ((f.theta1_rad - f.theta0_rad) / span_s(f) - free_drift_rad_s(s, f)) / se;
    c += z * z;
  }
  return c;
}

// The true resonator as the audit's parameters (no catalogue effect, pickoffs
// ideal, so the readout distortion and the pump's gap term are zero).
detail::Params true_params(const bench::Scenario& s) {
  const auto& r = s.resonator;
  detail::Params p{};
  p[detail::kNu] = r.nu_per_s();
  p[detail::kDnuC] = r.nu_per_s() * r.dmu * std::cos(4.0 * r.th_mu_rad);
  p[detail::kDnuS] = r.nu_per_s() * r.dmu * std::sin(4.0 * r.th_mu_rad);
  p[detail::kK] = r.angular_gain;
  p[detail::kCor] = 1.0;
  return p;
}

}  // namespace

TEST_GROUP(AuditAngleDrift){};

TEST(AuditAngleDrift, ANullsExcitationSegmentDriftIsAtItsWhiteNoiseOverItsEndRowsSpan) {
  // GIVEN the benchmark's design-1 null telemetry (no effect concealed)
  auto s = bench::random_scenario(bench::Design::telemetry, 360.0, kSeed);
  s.temp_cycles = true;
  const auto rec = bench::simulate(s);
  const auto d = detail::build_dataset(rec, 12000);
  CHECK_TRUE(d.forced.size() >= 40);
  const auto n = static_cast<double>(d.forced.size());
  const auto& t = rec.column("t_s");
  // WHEN each drift is read over the time between its end rows
  const double c_rows =
      chi2(s, d, [&](const detail::ForcedSegment& f) { return t[f.last_row] - t[f.first_row]; });
  // THEN it is at its white noise (chi^2 within 1.5x the count, not below n/1.5)
  CHECK_TRUE(c_rows < 1.5 * n);
  CHECK_TRUE(c_rows > n / 1.5);
  // AND over the three-row means' span (t1 - t0) it misses by far more: the
  // rate steps make K Omega / 2 up to 0.14 rad/s, two rows (10 ms) of 4-10 s
  // are 1e-4 to 3e-4 rad/s, against a noise of about 4e-6 rad/s
  const double c_means = chi2(s, d, [](const detail::ForcedSegment& f) { return f.t1_s - f.t0_s; });
  CHECK_TRUE(c_means > 10.0 * n);
}

TEST(AuditAngleDrift, TheAuditsAngleResidualsOfANullAreAtTheirWhiteNoiseAgainstTheTrueResonator) {
  // GIVEN the same null and the true resonator's parameters
  auto s = bench::random_scenario(bench::Design::telemetry, 360.0, kSeed);
  s.temp_cycles = true;
  auto d = detail::build_dataset(bench::simulate(s), 12000);
  for (auto& f : d.forced)
    f.angle_sigma_rad_s = 1.0;  // every segment's drift, as the audit marks those it uses
  // WHEN the audit's angle residuals are taken there, over their own white noise
  const auto r = detail::angle_residuals(d, true_params(s));
  LONGS_EQUAL(d.forced.size(), r.size());
  double c = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double z = r[i] / d.forced[i].angle_se_rad_s;
    c += z * z;
  }
  // THEN their chi^2 is at the count (over the means' span it is over 10x it,
  // the first test)
  const auto n = static_cast<double>(r.size());
  CHECK_TRUE(c < 1.5 * n);
  CHECK_TRUE(c > n / 1.5);
}

// The firmware and sim_target keep function-local statics beyond one test.
TEST_GROUP_WITHOUT_LEAK_CHECK(AuditAngleDriftFirmware);

TEST(AuditAngleDriftFirmware, AFirmwareNullsStillSegmentsReadTheRateOverTheirSpanAsItsIntegral) {
  // GIVEN the benchmark's design-2 null on the firmware's telemetry: two of
  // its still segments hold the start (39.9-45.15 s) and the end (100.5-115.7
  // s) of the table's 1 s ramps to 10.85 deg/s
  const auto s = bench::test::firmware_design(2026, 2);
  auto d = detail::build_dataset(bench::simulate(s), 12000);
  for (auto& f : d.forced)
    f.angle_sigma_rad_s = 1.0;
  // WHEN the audit's angle residuals are taken against the true resonator
  const auto r = detail::angle_residuals(d, true_params(s));
  // THEN every segment longer than 3 s is within 3 of its white-noise sigmas
  // (with the rows' mean rate in place of its integral over the span the two
  // were off by -7.2e-6 and -6.3e-6 rad/s, the first -5.4 sigma: K/2 of the
  // mean's error, which weighs the two end rows twice as much as the integral)
  int still = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (d.forced[i].angle_span_s < 3.0) continue;
    ++still;
    const double z = r[i] / d.forced[i].angle_se_rad_s;
    CHECK_TEXT(std::abs(z) < 3.0, std::to_string(z).c_str());
  }
  CHECK_TRUE(still >= 2);
}
