// SPDX-License-Identifier: MIT
#pragma once

#include <deque>
#include <vector>

#include "hal/can.hpp"

namespace hrg::test {

// CanBus fake with a back door: tests queue received frames, read what was
// sent, set the controller state and make send() refuse.
class FakeCanBus final : public hal::CanBus {
 public:
  // Back door.
  void push_rx(const hal::CanFrame& f) { rx_.push_back(f); }
  std::vector<hal::CanFrame>& sent() { return sent_; }
  void set_state(hal::CanState s) { state_ = s; }
  void set_send_result(hal::Status s) { send_result_ = s; }
  const std::vector<hal::CanFilter>& filters() const { return filters_; }
  int restart_calls() const { return restart_calls_; }

  // CanBus.
  hal::Status send(const hal::CanFrame& f) override {
    if (state_ == hal::CanState::bus_off) return hal::Status::bus_off;
    if (send_result_ != hal::Status::ok) {
      if (send_result_ == hal::Status::would_block) ++counters_.tx_queue_full;
      return send_result_;
    }
    sent_.push_back(f);
    ++counters_.tx_frames;
    return hal::Status::ok;
  }
  hal::Status receive(hal::CanFrame& f) override {
    if (rx_.empty()) return hal::Status::would_block;
    f = rx_.front();
    rx_.pop_front();
    ++counters_.rx_frames;
    return hal::Status::ok;
  }
  hal::Status set_filters(std::span<const hal::CanFilter> f) override {
    filters_.assign(f.begin(), f.end());
    return hal::Status::ok;
  }
  hal::CanState state() const override { return state_; }
  hal::Status restart() override {
    ++restart_calls_;
    ++counters_.restarts;
    state_ = hal::CanState::error_active;
    return hal::Status::ok;
  }
  hal::CanCounters counters() const override { return counters_; }

 private:
  std::deque<hal::CanFrame> rx_;
  std::vector<hal::CanFrame> sent_;
  std::vector<hal::CanFilter> filters_;
  hal::CanState state_ = hal::CanState::error_active;
  hal::Status send_result_ = hal::Status::ok;
  hal::CanCounters counters_{};
  int restart_calls_ = 0;
};

}  // namespace hrg::test
