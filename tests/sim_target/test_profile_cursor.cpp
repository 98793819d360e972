// SPDX-License-Identifier: MIT
// ProfileCursor: the full-rate integrator's per-sample view of a profile. Ramps
// and steps give Profile::value's bits; a sine advanced by rotation stays
// within the stated bound amplitude (kReanchorSteps 4 eps + 4 eps |phase|)
// over one hour of 100 kHz steps.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>

#include "sim_target/profile.hpp"

#include "support/cpputest.hpp"

using namespace hrg::sim;

namespace {

// Profile::integral as it was before the cursor took it over: a search for
// each breakpoint and each value.
double searched_integral(const Profile& p, double t0_s, double t1_s) {
  double sum = 0.0;
  double t = t0_s;
  while (t < t1_s) {
    const double e = std::min(t1_s, p.next_breakpoint_s(t));
    if (p.kind() == Profile::Kind::steps) {
      sum += p.value(0.5 * (t + e)) * (e - t);
    } else {
      sum += 0.5 * (p.value(t) + p.value(e)) * (e - t);
    }
    t = e;
  }
  return sum;
}

}  // namespace

TEST_GROUP(ProfileCursor){};

TEST(ProfileCursor, RampsAndStepsGiveTheSameBitsAsValue) {
  const Profile ramps = Profile::ramps({{0.5, 0.0}, {2.0, 4.0}, {3.0, 4.0}, {3.5, -1.0}});
  const Profile steps = Profile::steps({{1.0, 2.0}, {3.0, -1.0}});
  ProfileCursor r(&ramps);
  ProfileCursor s(&steps);
  const double h = 1e-5;
  for (uint64_t k = 0; k < 400'000; ++k) {
    const double t = static_cast<double>(k) * h + 0.5 * h;
    CHECK_EQUAL(ramps.value(t), r.value(t, k > 0, h));
    CHECK_EQUAL(steps.value(t), s.value(t, k > 0, h));
  }
  // A jump back in time searches again.
  CHECK_EQUAL(ramps.value(1.0), r.value(1.0, false, h));
}

TEST(ProfileCursor, SineByRotationStaysWithinItsBoundOverOneHour) {
  const double amplitude = 3.0;
  const double f_hz = 1.0;
  const double phase0 = 0.3;
  const Profile p = Profile::sine(amplitude, f_hz, phase0);
  ProfileCursor c(&p);
  const double h = 1e-5;
  const uint64_t steps = 360'000'000;  // one hour at 100 kHz
  const double eps = std::numeric_limits<double>::epsilon();
  const double phase_max = 2.0 * std::numbers::pi * f_hz * 3600.0 + phase0;
  const double bound = amplitude * (static_cast<double>(ProfileCursor::kReanchorSteps) * 4.0 * eps +
                                    4.0 * eps * phase_max);
  double worst = 0.0;
  for (uint64_t k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k) * h + 0.5 * h;
    const double v = c.value(t, k > 0, h);
    if (k % 97 == 0) worst = std::fmax(worst, std::fabs(v - p.value(t)));
  }
  std::printf("\nsine cursor over 1 h: worst error %.2e of bound %.2e\n", worst, bound);
  CHECK(worst <= bound);
  CHECK(worst > 0.0);  // the rotation is really used (an exact sin would give 0)
}

TEST(ProfileCursor, ConstantOverHoldsOnlyWhereTheValueCannotChange) {
  const Profile ramps = Profile::ramps({{0.5, 0.0}, {2.0, 4.0}, {3.0, 4.0}, {3.5, -1.0}});
  const Profile steps = Profile::steps({{1.0, 2.0}, {3.0, -1.0}});
  const Profile sine = Profile::sine(1.0, 1.0, 0.0);
  ProfileCursor r(&ramps);
  ProfileCursor s(&steps);
  ProfileCursor c(&sine);
  double v = 0.0;
  CHECK_TRUE(r.constant_over(0.0, 0.4, v));  // before the first point
  CHECK_EQUAL(ramps.value(0.2), v);
  CHECK_FALSE(r.constant_over(0.6, 0.7, v));  // rising segment
  CHECK_TRUE(r.constant_over(2.1, 2.9, v));   // flat segment between equal values
  CHECK_EQUAL(ramps.value(2.5), v);
  CHECK_FALSE(r.constant_over(2.9, 3.1, v));  // across a breakpoint
  CHECK_TRUE(r.constant_over(3.6, 1e4, v));   // after the last point
  CHECK_EQUAL(ramps.value(100.0), v);
  CHECK_TRUE(s.constant_over(1.0, 2.999, v));
  CHECK_EQUAL(2.0, v);
  CHECK_FALSE(s.constant_over(2.0, 3.0, v));  // the jump at 3 s is inside
  CHECK_FALSE(c.constant_over(0.0, 1e-5, v));
}

TEST(ProfileCursor, IntegralBlockByBlockGivesTheBitsOfTheSearchedIntegral) {
  // Spans of 1 ms (the board's blocks) through corners, a span over several
  // pieces, one before the first point and one back in time: the cursor's
  // integral against a search per breakpoint and per value, to the bit.
  const Profile ramps =
      Profile::ramps({{0.5, 0.0}, {2.0, 4.0}, {3.0, 4.0}, {3.5, -1.0}}).add_offset(0.25);
  const Profile steps = Profile::steps({{1.0, 2.0}, {3.0, -1.0}});
  for (const Profile* p : {&ramps, &steps}) {
    ProfileCursor c(p);
    for (int k = 0; k < 4000; ++k) {
      const double t0 = k * 1e-3;
      const double t1 = (k + 1) * 1e-3;
      CHECK_EQUAL(searched_integral(*p, t0, t1), c.integral(t0, t1));
    }
    CHECK_EQUAL(searched_integral(*p, 0.1, 3.7), c.integral(0.1, 3.7));
    CHECK_EQUAL(searched_integral(*p, 0.2, 0.3), c.integral(0.2, 0.3));
    CHECK_EQUAL(searched_integral(*p, 2.9, 3.2), p->integral(2.9, 3.2));
  }
  // Constant and sine: the closed forms.
  const Profile sine = Profile::sine(1.0, 1.0, 0.3);
  ProfileCursor c(&sine);
  CHECK_EQUAL(sine.integral(0.1, 0.35), c.integral(0.1, 0.35));
  // ramps: 0.25 * 3.5 + the trapezoids 3 + 4 + 0.75 = 8.625 over [0, 3.5]
  ProfileCursor r(&ramps);
  DOUBLES_EQUAL(8.625, r.integral(0.0, 3.5), 1e-14);
}
