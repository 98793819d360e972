// SPDX-License-Identifier: MIT
#pragma once

// In-memory CAN controller for the simulated target. Frames the firmware
// sends wait in a TX queue of fixed depth and leave it at a fixed rate as the
// simulated clock advances (tick()); tests read what went out, inject received
// frames and force bus-off through the back door.

#include <vector>

#include "hal/can.hpp"
#include "sim_target/sim_config.hpp"

namespace hrg::sim {

class SimCan final : public hal::CanBus {
 public:
  explicit SimCan(const CanConfig& c = {}) { configure(c); }
  void configure(const CanConfig& c);

  // hal::CanBus
  hal::Status send(const hal::CanFrame& frame) override;
  hal::Status receive(hal::CanFrame& frame) override;
  hal::Status set_filters(std::span<const hal::CanFilter> filters) override;
  hal::CanState state() const override { return state_; }
  hal::Status restart() override;
  hal::CanCounters counters() const override { return counters_; }

  // Back door (tests and the simulated board).
  void tick(double dt_s);  // moves queued frames to sent() at the bus rate
  const std::vector<hal::CanFrame>& sent() const { return sent_; }
  void clear_sent() { sent_.clear(); }
  void inject_rx(const hal::CanFrame& frame);  // as if received from the bus (filters apply)
  void force_bus_off();                        // drops the TX queue, counts a bus-off event
  void set_state(hal::CanState s) { state_ = s; }
  std::size_t tx_pending() const { return tx_.size(); }

 private:
  CanConfig config_;
  std::vector<hal::CanFrame> tx_;  // front = oldest; short queues, so erase() at the front is fine
  std::vector<hal::CanFrame> rx_;
  std::vector<hal::CanFrame> sent_;
  std::vector<hal::CanFilter> filters_;
  hal::CanState state_ = hal::CanState::error_active;
  hal::CanCounters counters_;
  double tx_credit_ = 0.0;
};

}  // namespace hrg::sim
