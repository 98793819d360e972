// SPDX-License-Identifier: MIT
// Linux target against a real kernel (run inside the test VM, see tools/vm/):
// SocketCAN on vcan0 (send, receive, filters, error frames, bus-off and
// restart), a full TX queue on vcan1 (a tbf qdisc limits its rate), and
// libgpiod lines on a gpio-sim chip read back through gpio-sim's sysfs.
// Environment: HRG_GPIO_CHIP (chip label or name), HRG_GPIO_SYSFS (directory
// holding sim_gpioN/).
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "hal/linux/gpiod_line.hpp"
#include "hal/linux/linux_clock.hpp"
#include "hal/linux/socket_can.hpp"

#include "support/cpputest.hpp"

using namespace hrg::hal;
using namespace hrg::hal::linux_board;

namespace {

// A second raw socket on the same bus: what another node sends and sees.
class Peer {
 public:
  explicit Peer(const char* ifname) {
    fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK, CAN_RAW);
    ifreq ifr{};
    std::strncpy(ifr.ifr_name, ifname, IFNAMSIZ - 1);
    ::ioctl(fd_, SIOCGIFINDEX, &ifr);
    sockaddr_can a{};
    a.can_family = AF_CAN;
    a.can_ifindex = ifr.ifr_ifindex;
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  ~Peer() { ::close(fd_); }
  bool send_raw(uint32_t can_id, uint8_t len, const uint8_t* data) {
    can_frame cf{};
    cf.can_id = can_id;
    cf.len = len;
    if (len > 0) std::memcpy(cf.data, data, len);
    return ::write(fd_, &cf, sizeof cf) == static_cast<ssize_t>(sizeof cf);
  }
  bool send(uint32_t id, uint8_t b0) { return send_raw(id, 1, &b0); }
  // Error frame as a controller would report it (class in the id, details in data).
  bool send_error(uint32_t err_class, uint8_t crtl = 0) {
    uint8_t d[8] = {0, crtl, 0, 0, 0, 0, 0, 0};
    return send_raw(CAN_ERR_FLAG | err_class, 8, d);
  }
  int receive(can_frame& cf) {
    for (int i = 0; i < 200; ++i) {
      if (::read(fd_, &cf, sizeof cf) == static_cast<ssize_t>(sizeof cf)) return 1;
      ::usleep(1000);
    }
    return 0;
  }

 private:
  int fd_ = -1;
};

// Polls receive() for up to 200 ms (frames loop back through the kernel).
Status receive_within(SocketCan& can, CanFrame& f) {
  Status s = Status::would_block;
  for (int i = 0; i < 200 && s == Status::would_block; ++i) {
    s = can.receive(f);
    if (s == Status::would_block) ::usleep(1000);
  }
  return s;
}

void drain(SocketCan& can) {
  CanFrame f;
  while (receive_within(can, f) == Status::ok) {
  }
}

std::string read_sysfs(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) return "<missing " + path + ">";
  char buf[64] = {};
  const std::size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  std::string s(buf, n);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
    s.pop_back();
  return s;
}

void write_sysfs(const std::string& path, const char* value) {
  FILE* f = std::fopen(path.c_str(), "w");
  CHECK_TEXT(f != nullptr, path.c_str());
  std::fputs(value, f);
  std::fclose(f);
}

const char* env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? v : "";
}

}  // namespace

TEST_GROUP(SocketCanKernel) {
  SocketCan can;
  void setup() override { CHECK(Status::ok == can.open("vcan0")); }
};

TEST(SocketCanKernel, AFrameSentIsSeenByAnotherNodeBitForBit) {
  Peer peer("vcan0");
  CanFrame f;
  f.id = 0x101;
  f.len = 8;
  for (uint8_t i = 0; i < 8; ++i)
    f.data[i] = static_cast<uint8_t>(0xA0 + i);
  CHECK(Status::ok == can.send(f));
  can_frame cf{};
  CHECK(peer.receive(cf) == 1);
  LONGS_EQUAL(0x101, cf.can_id);
  LONGS_EQUAL(8, cf.len);
  LONGS_EQUAL(0xA7, cf.data[7]);
  f.extended = true;
  f.id = 0x1234567;
  f.len = 2;
  CHECK(Status::ok == can.send(f));
  CHECK(peer.receive(cf) == 1);
  LONGS_EQUAL(CAN_EFF_FLAG | 0x1234567u, cf.can_id);
  LONGS_EQUAL(2, can.counters().tx_frames);
}

TEST(SocketCanKernel, FiltersPassOnlyMatchingIdentifiers) {
  Peer peer("vcan0");
  const CanFilter commands[] = {{0x080, 0x7F0}};
  CHECK(Status::ok == can.set_filters(commands));
  CHECK(peer.send(0x100, 1));  // telemetry range: filtered out
  CHECK(peer.send(0x083, 2));  // command range: passes
  CanFrame f;
  CHECK(Status::ok == receive_within(can, f));
  LONGS_EQUAL(0x083, f.id);
  LONGS_EQUAL(2, f.data[0]);
  CHECK(Status::would_block == receive_within(can, f));
  CHECK(Status::ok == can.set_filters({}));  // everything again
  CHECK(peer.send(0x100, 3));
  CHECK(Status::ok == receive_within(can, f));
  LONGS_EQUAL(0x100, f.id);
  LONGS_EQUAL(2, can.counters().rx_frames);
}

TEST(SocketCanKernel, ErrorFramesChangeTheStateAndAreNotReturnedAsData) {
  Peer peer("vcan0");
  CHECK(peer.send_error(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING));
  drain(can);
  CHECK(CanState::error_warning == can.state());
  CHECK(peer.send_error(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE));
  drain(can);
  CHECK(CanState::error_passive == can.state());
  CHECK(peer.send_error(CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE));
  drain(can);
  CHECK(CanState::error_active == can.state());
  LONGS_EQUAL(3, can.counters().error_frames);
  LONGS_EQUAL(0, can.counters().rx_frames);
}

TEST(SocketCanKernel, BusOffRefusesSendsUntilRestartAndIsSurvived) {
  Peer peer("vcan0");
  CHECK(peer.send_error(CAN_ERR_BUSOFF));
  drain(can);
  CHECK(CanState::bus_off == can.state());
  LONGS_EQUAL(1, can.counters().bus_off_events);
  CanFrame f;
  f.id = 0x105;
  f.len = 1;
  CHECK(Status::bus_off == can.send(f));
  CHECK(is_retryable(Status::bus_off));
  // A second bus-off report while already off is not a new event.
  CHECK(peer.send_error(CAN_ERR_BUSOFF));
  drain(can);
  LONGS_EQUAL(1, can.counters().bus_off_events);
  CHECK(Status::ok == can.restart());
  CHECK(CanState::error_active == can.state());
  LONGS_EQUAL(1, can.counters().restarts);
  CHECK(Status::ok == can.send(f));
  can_frame cf{};
  CHECK(peer.receive(cf) == 1);
  LONGS_EQUAL(0x105, cf.can_id);
  // The controller reporting its own restart also clears bus-off.
  CHECK(peer.send_error(CAN_ERR_BUSOFF));
  drain(can);
  CHECK(peer.send_error(CAN_ERR_RESTARTED));
  drain(can);
  CHECK(CanState::error_active == can.state());
  LONGS_EQUAL(2, can.counters().bus_off_events);
}

TEST_GROUP(SocketCanQueue){};

TEST(SocketCanQueue, AFullTxQueueIsCountedReportedAndNeverBlocks) {
  // GIVEN vcan1 drained by a 100 kbit/s token bucket and a small socket buffer
  SocketCan can;
  CHECK(Status::ok == can.open("vcan1"));
  CHECK(Status::ok == can.set_send_buffer(4096));
  LinuxClock clock;
  CanFrame f;
  f.id = 0x100;
  f.len = 8;
  // WHEN 2000 frames (2.2 s of the bucket's rate) are offered at once
  int ok = 0;
  int full = 0;
  const uint64_t t0 = clock.now_ns();
  for (int i = 0; i < 2000; ++i) {
    const Status s = can.send(f);
    if (s == Status::ok) ++ok;
    if (s == Status::would_block) ++full;
  }
  const uint64_t dt_ns = clock.now_ns() - t0;
  // THEN most are refused as would_block, every refusal is counted, and the
  // whole burst returned far faster than the bucket could send it (no blocking)
  std::printf("\n  tx queue: %d sent, %d refused (queue full), burst took %.3f ms\n", ok, full,
              static_cast<double>(dt_ns) * 1e-6);
  CHECK(full > 1000);
  LONGS_EQUAL(2000, ok + full);
  LONGS_EQUAL(full, can.counters().tx_queue_full);
  LONGS_EQUAL(ok, can.counters().tx_frames);
  CHECK(dt_ns < 500'000'000ull);
  // AND once the queue has drained, sending works again
  ::usleep(300'000);
  CHECK(Status::ok == can.send(f));
}

TEST_GROUP(GpiodKernel) {
  std::string sysfs;
  void setup() override { sysfs = env("HRG_GPIO_SYSFS"); }
  LineConfig line(unsigned offset, bool active_low = false) {
    LineConfig c;
    c.chip = env("HRG_GPIO_CHIP");
    c.offset = offset;
    c.active_low = active_low;
    return c;
  }
};

TEST(GpiodKernel, TheOutputLineFollowsWritesOnTheSimulatedChip) {
  GpiodOutput out;
  CHECK(Status::ok == out.open(line(0)));
  STRCMP_EQUAL("0", read_sysfs(sysfs + "/sim_gpio0/value").c_str());  // requested inactive
  CHECK(Status::ok == out.write(true));
  STRCMP_EQUAL("1", read_sysfs(sysfs + "/sim_gpio0/value").c_str());
  CHECK(Status::ok == out.write(false));
  STRCMP_EQUAL("0", read_sysfs(sysfs + "/sim_gpio0/value").c_str());
}

TEST(GpiodKernel, AnActiveLowOutputDrivesThePinLowWhenActive) {
  GpiodOutput out;
  CHECK(Status::ok == out.open(line(2, true)));
  STRCMP_EQUAL("1", read_sysfs(sysfs + "/sim_gpio2/value").c_str());
  CHECK(Status::ok == out.write(true));
  STRCMP_EQUAL("0", read_sysfs(sysfs + "/sim_gpio2/value").c_str());
}

TEST(GpiodKernel, TheFaultInputReadsThePullSetOnTheSimulatedChip) {
  GpiodInput in;
  CHECK(Status::ok == in.open(line(1)));
  bool v = true;
  write_sysfs(sysfs + "/sim_gpio1/pull", "pull-down");
  CHECK(Status::ok == in.read(v));
  CHECK_FALSE(v);
  write_sysfs(sysfs + "/sim_gpio1/pull", "pull-up");
  CHECK(Status::ok == in.read(v));
  CHECK(v);
  write_sysfs(sysfs + "/sim_gpio1/pull", "pull-down");
}

TEST(GpiodKernel, ALineHeldByAnotherRequestIsBusy) {
  GpiodOutput a;
  GpiodOutput b;
  CHECK(Status::ok == a.open(line(3)));
  CHECK(Status::busy == b.open(line(3)));
}
