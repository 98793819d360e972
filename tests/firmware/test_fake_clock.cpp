// SPDX-License-Identifier: MIT
#include "fakes/fake_clock.hpp"

#include "support/cpputest.hpp"

using hrg::fakes::FakeClock;
using hrg::hal::Status;

TEST_GROUP(FakeClock){};

TEST(FakeClock, StartsAtZeroAndMovesOnlyByTheBackDoor) {
  FakeClock c;
  LONGS_EQUAL(0, c.now_ns());
  c.advance_ns(250);
  c.advance_ns(50);
  LONGS_EQUAL(300, c.now_ns());
  c.set_now_ns(7);
  LONGS_EQUAL(7, c.now_ns());
}

TEST(FakeClock, SleepingJumpsToAFutureDeadline) {
  FakeClock c;
  c.set_now_ns(100);
  CHECK(Status::ok == c.sleep_until_ns(1'000));
  LONGS_EQUAL(1'000, c.now_ns());
  LONGS_EQUAL(1, c.sleeps());
}

TEST(FakeClock, SleepingUntilAPastDeadlineReportsTimeoutAndDoesNotMove) {
  FakeClock c;
  c.set_now_ns(5'000);
  CHECK(Status::timeout == c.sleep_until_ns(4'000));
  LONGS_EQUAL(5'000, c.now_ns());
}

TEST(FakeClock, InLockstepSleepingReturnsAtOnceWithoutMoving) {
  FakeClock c;
  c.set_lockstep(true);
  c.set_now_ns(100);
  CHECK(Status::ok == c.sleep_until_ns(1'000));
  LONGS_EQUAL(100, c.now_ns());
}
