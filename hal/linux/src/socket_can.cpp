// SPDX-License-Identifier: MIT
#include "hal/linux/socket_can.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/netlink.h>
#include <linux/can/raw.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace hrg::hal::linux_board {

namespace {

constexpr std::size_t kMaxFilters = 16;

// Appends a netlink attribute; returns a pointer to it (for nesting) or nullptr
// when the buffer is full.
rtattr* add_attr(nlmsghdr* n, std::size_t cap, unsigned short type, const void* data,
                 std::size_t len) {
  const std::size_t attr_len = RTA_LENGTH(len);
  if (NLMSG_ALIGN(n->nlmsg_len) + RTA_ALIGN(attr_len) > cap) return nullptr;
  auto* rta = reinterpret_cast<rtattr*>(reinterpret_cast<char*>(n) + NLMSG_ALIGN(n->nlmsg_len));
  rta->rta_type = type;
  rta->rta_len = static_cast<unsigned short>(attr_len);
  if (len > 0) std::memcpy(RTA_DATA(rta), data, len);
  n->nlmsg_len = static_cast<uint32_t>(NLMSG_ALIGN(n->nlmsg_len) + RTA_ALIGN(attr_len));
  return rta;
}

void end_nest(nlmsghdr* n, rtattr* nest) {
  nest->rta_len = static_cast<unsigned short>(reinterpret_cast<char*>(n) + n->nlmsg_len -
                                              reinterpret_cast<char*>(nest));
}

// Sends RTM_NEWLINK with IFLA_CAN_RESTART; returns 0 or a negative errno.
int netlink_can_restart(int ifindex) {
  struct {
    nlmsghdr n;
    ifinfomsg i;
    char buf[128];
  } req{};
  req.n.nlmsg_len = NLMSG_LENGTH(sizeof(ifinfomsg));
  req.n.nlmsg_type = RTM_NEWLINK;
  req.n.nlmsg_flags = NLM_F_REQUEST | NLM_F_ACK;
  req.i.ifi_family = AF_UNSPEC;
  req.i.ifi_index = ifindex;
  const std::size_t cap = sizeof req;
  rtattr* linkinfo = add_attr(&req.n, cap, IFLA_LINKINFO, nullptr, 0);
  add_attr(&req.n, cap, IFLA_INFO_KIND, "can", 3);
  rtattr* data = add_attr(&req.n, cap, IFLA_INFO_DATA, nullptr, 0);
  const uint32_t one = 1;
  add_attr(&req.n, cap, IFLA_CAN_RESTART, &one, sizeof one);
  end_nest(&req.n, data);
  end_nest(&req.n, linkinfo);

  const int fd = ::socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC, NETLINK_ROUTE);
  if (fd < 0) return -errno;
  sockaddr_nl addr{};
  addr.nl_family = AF_NETLINK;
  int result = -EIO;
  if (::sendto(fd, &req, req.n.nlmsg_len, 0, reinterpret_cast<sockaddr*>(&addr), sizeof addr) >=
      0) {
    char reply[256];
    const ssize_t r = ::recv(fd, reply, sizeof reply, 0);
    if (r >= static_cast<ssize_t>(NLMSG_LENGTH(sizeof(nlmsgerr)))) {
      const auto* h = reinterpret_cast<const nlmsghdr*>(reply);
      if (h->nlmsg_type == NLMSG_ERROR) {
        result = reinterpret_cast<const nlmsgerr*>(NLMSG_DATA(h))->error;
      }
    }
  } else {
    result = -errno;
  }
  ::close(fd);
  return result;
}

}  // namespace

SocketCan::~SocketCan() { close(); }

void SocketCan::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Status SocketCan::open(const char* interface) {
  close();
  if (interface == nullptr || std::strlen(interface) >= IFNAMSIZ) return Status::invalid_argument;
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return errno == EAFNOSUPPORT ? Status::not_supported : Status::io_error;
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface, IFNAMSIZ - 1);
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
    ::close(fd);
    return Status::invalid_argument;
  }
  // Every error class: state changes, bus-off, restarts, protocol errors.
  const can_err_mask_t err_mask = CAN_ERR_MASK;
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) < 0 ||
      ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
    ::close(fd);
    return Status::io_error;
  }
  fd_ = fd;
  ifindex_ = ifr.ifr_ifindex;
  state_ = CanState::error_active;
  return Status::ok;
}

Status SocketCan::set_send_buffer(int bytes) {
  if (fd_ < 0) return Status::closed;
  if (::setsockopt(fd_, SOL_SOCKET, SO_SNDBUF, &bytes, sizeof bytes) < 0) return Status::io_error;
  return Status::ok;
}

Status SocketCan::send(const CanFrame& frame) {
  if (fd_ < 0) return Status::closed;
  if (frame.len > 8 || frame.id > (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK)) {
    return Status::invalid_argument;
  }
  if (state_ == CanState::bus_off) return Status::bus_off;
  can_frame cf{};
  cf.can_id = frame.extended ? (frame.id | CAN_EFF_FLAG) : frame.id;
  cf.len = frame.len;
  std::memcpy(cf.data, frame.data.data(), frame.len);
  const ssize_t n = ::send(fd_, &cf, sizeof cf, MSG_DONTWAIT);
  if (n == static_cast<ssize_t>(sizeof cf)) {
    ++counters_.tx_frames;
    return Status::ok;
  }
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) {
    // Socket buffer or the device queue is full: drop, count, report.
    ++counters_.tx_queue_full;
    return Status::would_block;
  }
  if (n < 0 && errno == ENETDOWN) return Status::busy;  // interface down (restarting)
  return Status::io_error;
}

Status SocketCan::receive(CanFrame& frame) {
  if (fd_ < 0) return Status::closed;
  // Error frames are consumed here and never returned; loop until a data frame.
  for (;;) {
    can_frame cf{};
    const ssize_t n = ::recv(fd_, &cf, sizeof cf, MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return Status::would_block;
      if (errno == EINTR) continue;
      return errno == ENETDOWN ? Status::busy : Status::io_error;
    }
    if (n != static_cast<ssize_t>(sizeof cf)) continue;  // not a classic frame
    if (cf.can_id & CAN_ERR_FLAG) {
      on_error_frame(cf.can_id & CAN_ERR_MASK, cf.data);
      continue;
    }
    if (cf.can_id & CAN_RTR_FLAG) continue;  // the protocol has no remote frames
    frame.extended = (cf.can_id & CAN_EFF_FLAG) != 0;
    frame.id = cf.can_id & (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    frame.len = cf.len > 8 ? 8 : cf.len;
    frame.data = {};
    std::memcpy(frame.data.data(), cf.data, frame.len);
    ++counters_.rx_frames;
    return Status::ok;
  }
}

void SocketCan::on_error_frame(uint32_t err_class, const uint8_t* data) {
  ++counters_.error_frames;
  if (err_class & CAN_ERR_BUSOFF) {
    if (state_ != CanState::bus_off) ++counters_.bus_off_events;
    state_ = CanState::bus_off;
    return;
  }
  if (err_class & CAN_ERR_RESTARTED) {
    state_ = CanState::error_active;
    return;
  }
  if (err_class & CAN_ERR_CRTL) {
    const uint8_t c = data[1];
    if (c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      state_ = CanState::error_passive;
    } else if (c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      state_ = CanState::error_warning;
    } else if (c & CAN_ERR_CRTL_ACTIVE) {
      state_ = CanState::error_active;
    }
  }
}

Status SocketCan::set_filters(std::span<const CanFilter> filters) {
  if (fd_ < 0) return Status::closed;
  if (filters.size() > kMaxFilters) return Status::invalid_argument;
  can_filter kf[kMaxFilters];
  std::size_t n = 0;
  for (const auto& f : filters) {
    kf[n].can_id = f.id & CAN_EFF_MASK;
    kf[n].can_mask = f.mask & CAN_EFF_MASK;
    ++n;
  }
  if (n == 0) {  // accept everything
    kf[0].can_id = 0;
    kf[0].can_mask = 0;
    n = 1;
  }
  if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, kf, static_cast<socklen_t>(n * sizeof kf[0])) <
      0) {
    return Status::io_error;
  }
  return Status::ok;
}

Status SocketCan::restart() {
  if (fd_ < 0) return Status::closed;
  const int r = netlink_can_restart(ifindex_);
  // -EOPNOTSUPP: a virtual CAN interface (no controller); -EINVAL: the controller
  // is not bus-off. Both leave nothing to restart.
  if (r != 0 && r != -EOPNOTSUPP && r != -EINVAL) {
    return r == -EPERM ? Status::not_supported : (r == -EBUSY ? Status::busy : Status::io_error);
  }
  ++counters_.restarts;
  state_ = CanState::error_active;
  return Status::ok;
}

}  // namespace hrg::hal::linux_board
