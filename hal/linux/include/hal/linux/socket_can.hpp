// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

#include "hal/can.hpp"

namespace hrg::hal::linux_board {

// CanBus over a raw SocketCAN socket (can0, vcan0, ...). The socket is
// non-blocking: send() never waits (a full TX queue returns would_block and is
// counted in tx_queue_full) and receive() returns would_block when empty.
// Error frames are subscribed to; they update state() and the counters as
// receive() drains the socket, and are not returned as data frames.
// Calling context: one thread (the executive). Not copyable.
class SocketCan final : public CanBus {
 public:
  SocketCan() = default;
  ~SocketCan() override;

  // Opens and binds `interface`. invalid_argument for an unknown interface,
  // not_supported when the kernel has no AF_CAN, io_error otherwise.
  Status open(const char* interface);
  void close();
  bool is_open() const { return fd_ >= 0; }

  Status send(const CanFrame& frame) override;
  Status receive(CanFrame& frame) override;
  Status set_filters(std::span<const CanFilter> filters) override;
  CanState state() const override { return state_; }
  // Asks the controller to restart (rtnetlink IFLA_CAN_RESTART; needs
  // CAP_NET_ADMIN). A virtual interface has no controller to restart: the
  // driver then only leaves its bus-off state. Counted in restarts.
  Status restart() override;
  CanCounters counters() const override { return counters_; }

  // Socket send buffer in bytes (SO_SNDBUF); smaller means the TX queue fills
  // sooner. Call after open().
  Status set_send_buffer(int bytes);
  int fd() const { return fd_; }

 private:
  void on_error_frame(uint32_t can_id, const uint8_t* data);

  int fd_ = -1;
  int ifindex_ = 0;
  CanState state_ = CanState::error_active;
  CanCounters counters_{};
};

}  // namespace hrg::hal::linux_board
