// SPDX-License-Identifier: MIT
#include "firmware/angle_output.hpp"

#include <cmath>
#include <numbers>

#include "support/cpputest.hpp"

using hrg::fw::AngleOutput;

namespace {
constexpr double kPi = std::numbers::pi;
}  // namespace

TEST_GROUP(AngleOutput){};

TEST(AngleOutput, ARotatingCaseGivesMinusTwoThetaOverK) {
  // GIVEN K = 0.554 and an input rate of 10 deg/s: theta_A' = -K Omega / 2
  const double k = 0.554, omega = 10.0 * kPi / 180, dt = 1e-3;
  AngleOutput out(k, dt);
  const double theta0 = 0.1;
  for (int i = 0; i <= 20'000; ++i) {  // 20 s: theta_A turns 55 deg (unwrapped by the chain)
    const double t = i * dt;
    out.update(theta0 - k * omega / 2 * t, 0.0, true);
  }
  // THEN the angle is the integral of the rate: 200 deg
  DOUBLES_EQUAL(omega * 20.0, out.angle_rad(), 1e-9);
  DOUBLES_EQUAL(omega, out.rate_rad_s(), 1e-9);
  CHECK(out.valid());
}

TEST(AngleOutput, TheDriftCorrectionAddsTheIntegralOfDOverK) {
  // With a constant drift D the pattern moves by D/2 per second while the
  // case is still: -2 theta' / K = -D / K, and the correction cancels it.
  const double k = 0.554, d = 3e-4, dt = 1e-3;
  AngleOutput out(k, dt);
  for (int i = 0; i <= 10'000; ++i)
    out.update(0.2 + d / 2 * i * dt, d, true);
  DOUBLES_EQUAL(-d / k * 10.0, out.raw_angle_rad(), 1e-9);
  // The trapezoid is exact for a constant D: one frame of D / K per update
  // (10001 updates), the raw angle moved over 10000 frames.
  DOUBLES_EQUAL(d / k * 10.001, out.correction_rad(), 1e-12);
  DOUBLES_EQUAL(d / k * 1e-3, out.angle_rad(), 1e-12);
}

TEST(AngleOutput, TheCorrectionIsTheTrapezoidOfDOverKAndRestartsAfterAGap) {
  // A linear ramp D = c t is integrated exactly by the trapezoid: c T^2 / 2.
  const double k = 0.5, c = 1e-3, dt = 1e-3;
  AngleOutput out(k, dt);
  for (int i = 0; i <= 1000; ++i)
    out.update(0.0, c * i * dt, true);
  DOUBLES_EQUAL(c * 1.0 * 1.0 / 2.0 / k, out.correction_rad(), 1e-12);
  // An invalid stretch adds nothing, and the first valid step after it does
  // not average its D with the one before the gap.
  const double before = out.correction_rad();
  out.update(0.0, 5.0, false);
  out.update(0.0, 2.0, true);
  DOUBLES_EQUAL(before + 2.0 / k * dt, out.correction_rad(), 1e-12);
}

TEST(AngleOutput, NoCorrectionIsIntegratedWhileInvalid) {
  AngleOutput out(0.5, 1e-3);
  for (int i = 0; i < 100; ++i)
    out.update(0.0, 1.0, false);
  DOUBLES_EQUAL(0.0, out.correction_rad(), 0.0);
  CHECK_FALSE(out.valid());
}

TEST(AngleOutput, RereferenceKeepsTheAngleWhileThePatternIsMovedOnPurpose) {
  AngleOutput out(0.5, 1e-3);
  for (int i = 0; i <= 100; ++i)
    out.update(-0.001 * i, 0.0, true);  // +0.4 rad of input
  const double before = out.angle_rad();
  DOUBLES_EQUAL(0.4, before, 1e-12);
  for (int i = 0; i < 100; ++i) {  // the pattern is driven by +0.3 rad
    out.rereference();
    out.update(-0.1 + 0.003 * i, 0.0, false);
  }
  DOUBLES_EQUAL(before, out.angle_rad(), 1e-12);
  out.update(0.197 - 0.001, 0.0, true);  // then the input moves it by 0.001 rad
  DOUBLES_EQUAL(before + 0.004, out.angle_rad(), 1e-12);
}
