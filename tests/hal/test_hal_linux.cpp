// SPDX-License-Identifier: MIT
// Linux target on any host (no CAN or GPIO needed): the clock is monotonic and
// sleeps to absolute deadlines; devices that are absent fail with a fatal
// status instead of crashing; closed devices say so. The kernel behaviour of
// SocketCAN and libgpiod is tested in the VM (test_hal_linux_kernel.cpp).
#include <cstdint>
#include <cstring>

#include <pthread.h>
#include <sched.h>

#include "hal/linux/gpiod_line.hpp"
#include "hal/linux/linux_clock.hpp"
#include "hal/linux/realtime.hpp"
#include "hal/linux/socket_can.hpp"

#include "support/cpputest.hpp"

using namespace hrg::hal;
using namespace hrg::hal::linux_board;

TEST_GROUP(LinuxClock){};

TEST(LinuxClock, TimeNeverGoesBackwards) {
  LinuxClock c;
  uint64_t prev = c.now_ns();
  for (int i = 0; i < 10000; ++i) {
    const uint64_t t = c.now_ns();
    CHECK(t >= prev);
    prev = t;
  }
}

TEST(LinuxClock, SleepingUntilAPastDeadlineReportsTimeoutWithoutSleeping) {
  LinuxClock c;
  const uint64_t past = c.now_ns() - 1'000'000;
  CHECK(Status::timeout == c.sleep_until_ns(past));
}

TEST(LinuxClock, SleepingUntilAFutureDeadlineReturnsAtOrAfterIt) {
  LinuxClock c;
  uint64_t deadline = c.now_ns();
  for (int i = 0; i < 5; ++i) {
    deadline += 1'000'000;  // 1 ms periods on absolute deadlines
    const Status s = c.sleep_until_ns(deadline);
    // A loaded machine may already be past the deadline: that is a reported miss.
    CHECK(s == Status::ok || s == Status::timeout);
    CHECK(c.now_ns() >= deadline);
  }
}

TEST_GROUP(LinuxDevices){};

TEST(LinuxDevices, AMissingCanInterfaceIsAFatalOpenError) {
  SocketCan can;
  const Status s = can.open("hrgnone0");
  CHECK(is_fatal(s));
  CHECK_FALSE(can.is_open());
  CHECK(is_fatal(can.open(nullptr)));
  CHECK(is_fatal(can.open("a-name-longer-than-ifnamsiz")));
}

TEST(LinuxDevices, AClosedCanBusRefusesEveryOperation) {
  SocketCan can;
  CanFrame f;
  CHECK(Status::closed == can.send(f));
  CHECK(Status::closed == can.receive(f));
  CHECK(Status::closed == can.set_filters({}));
  CHECK(Status::closed == can.restart());
  CHECK(CanState::error_active == can.state());
  LONGS_EQUAL(0, can.counters().tx_frames);
}

TEST(LinuxDevices, AMissingGpioChipIsAFatalOpenError) {
  GpiodOutput out;
  LineConfig cfg;
  cfg.chip = "/nonexistent/gpiochip";
  CHECK(Status::invalid_argument == out.open(cfg));
  CHECK(Status::closed == out.write(true));
  GpiodInput in;
  CHECK(Status::invalid_argument == in.open(cfg));
  bool v = false;
  CHECK(Status::closed == in.read(v));
}

TEST_GROUP(Realtime){};

TEST(Realtime, EveryRefusalIsReportedAndDescribed) {
  RealtimeRequest req;
  req.priority = 10;
  req.lock_memory = false;  // keep the test process unlocked
  const RealtimeReport r = setup_realtime(req);
  // Either granted (root with CAP_SYS_NICE) or refused with a reason.
  CHECK(r.fifo ? r.priority == 10 : r.fifo_errno != 0);
  char buf[256];
  const char* text = describe(r, buf, sizeof buf);
  CHECK(std::strstr(text, r.fifo ? "SCHED_FIFO 10" : "SCHED_FIFO refused") != nullptr);
  CHECK(std::strstr(text, "not requested") != nullptr);
  // Back to normal scheduling so the rest of the suite is not real-time.
  sched_param sp{};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
}
