// SPDX-License-Identifier: MIT
// Input profiles: constant, steps, ramps, sine, table file.
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "sim_target/profile.hpp"

#include "support/cpputest.hpp"

using namespace hrg::sim;

TEST_GROUP(Profile){};

TEST(Profile, StepsHoldEachValueUntilTheNextTime) {
  Profile p = Profile::steps({{1.0, 2.0}, {3.0, -1.0}});
  DOUBLES_EQUAL(2.0, p.value(0.0), 0.0);
  DOUBLES_EQUAL(2.0, p.value(2.999), 0.0);
  DOUBLES_EQUAL(-1.0, p.value(3.0), 0.0);
  DOUBLES_EQUAL(-1.0, p.value(100.0), 0.0);
  CHECK_FALSE(p.is_constant());
}

TEST(Profile, RampsInterpolateAndHoldTheEnds) {
  Profile p = Profile::ramps({{0.0, 0.0}, {2.0, 4.0}, {3.0, 4.0}});
  p.add_offset(0.5);
  DOUBLES_EQUAL(0.5, p.value(-1.0), 0.0);
  DOUBLES_EQUAL(3.5, p.value(1.5), 1e-15);
  DOUBLES_EQUAL(4.5, p.value(10.0), 0.0);
}

TEST(Profile, SineHasItsAmplitudeFrequencyAndPhase) {
  const Profile p = Profile::sine(2.0, 0.5, std::acos(-1.0) / 2.0);
  DOUBLES_EQUAL(2.0, p.value(0.0), 1e-15);
  DOUBLES_EQUAL(-2.0, p.value(1.0), 1e-15);
}

TEST(Profile, TableFileIsReadScaledAndCheckedLineByLine) {
  const std::string path = "test_profile_table.csv";
  std::FILE* f = std::fopen(path.c_str(), "w");
  CHECK(f != nullptr);
  std::fputs("t_s,rate_dps\n0, 0\n# comment\n10, 90\n", f);
  std::fclose(f);
  const Profile p = Profile::table_file(path, std::acos(-1.0) / 180.0);
  DOUBLES_EQUAL(std::acos(-1.0) / 4.0, p.value(5.0), 1e-15);
  f = std::fopen(path.c_str(), "w");
  std::fputs("0, 0\n5, 1\n4, 2\n", f);
  std::fclose(f);
  std::string err;
  try {
    Profile::table_file(path);
  } catch (const std::runtime_error& e) {
    err = e.what();
  }
  STRCMP_EQUAL("test_profile_table.csv:3: time does not increase", err.c_str());
  std::remove(path.c_str());
}

TEST(Profile, RejectsTimesThatDoNotIncrease) {
  CHECK_THROWS(std::invalid_argument, Profile::ramps({{1.0, 0.0}, {1.0, 1.0}}));
}

TEST(Profile, IntegralIsExactForEveryKind) {
  DOUBLES_EQUAL(6.0, Profile::constant(2.0).integral(1.0, 4.0), 1e-15);
  // steps: 1 on [0, 2), 3 from 2 on -> over [1, 3]: 1 + 3
  DOUBLES_EQUAL(4.0, Profile::steps({{0.0, 1.0}, {2.0, 3.0}}).integral(1.0, 3.0), 1e-15);
  // ramps 0 -> 2 over [0, 2], then held: over [1, 3]: 1.5 + 2
  DOUBLES_EQUAL(3.5, Profile::ramps({{0.0, 0.0}, {2.0, 2.0}}).integral(1.0, 3.0), 1e-15);
  // sine: integral of sin(2 pi t) over [0, 0.25] = 1 / (2 pi)
  DOUBLES_EQUAL(1.0 / (2.0 * std::acos(-1.0)), Profile::sine(1.0, 1.0, 0.0).integral(0.0, 0.25),
                1e-15);
}
