// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "hal/can.hpp"

namespace hrg::fakes {

// The tests' one CAN bus fake (the firmware's board and the CAN link's own
// tests). Allocation-free, so the firmware's no-allocation test can run on
// it. Back door: inject() queues a received frame (up to 16), the last 64
// frames sent are kept, set_state() and set_send_result() make send() refuse,
// the filters set and the restarts made are recorded.
class FakeCan final : public hal::CanBus {
 public:
  // CanBus.
  hal::Status send(const hal::CanFrame& f) override {
    if (state_ == hal::CanState::bus_off) return hal::Status::bus_off;
    if (send_result_ != hal::Status::ok) {
      if (send_result_ == hal::Status::would_block) ++counters_.tx_queue_full;
      return send_result_;
    }
    last_ = f;
    sent_[counters_.tx_frames % sent_.size()] = f;
    ++counters_.tx_frames;
    return hal::Status::ok;
  }
  hal::Status receive(hal::CanFrame& f) override {
    if (rx_head_ == rx_tail_) return hal::Status::would_block;
    f = rx_[rx_head_++ % rx_.size()];
    ++counters_.rx_frames;
    return hal::Status::ok;
  }
  hal::Status set_filters(std::span<const hal::CanFilter> f) override {
    if (f.size() > filters_.size()) return hal::Status::invalid_argument;
    filter_count_ = 0;
    for (const auto& x : f)
      filters_[filter_count_++] = x;
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

  // Back door.
  bool inject(const hal::CanFrame& f) {
    if (rx_tail_ - rx_head_ >= rx_.size()) return false;
    rx_[rx_tail_++ % rx_.size()] = f;
    return true;
  }
  void set_state(hal::CanState s) { state_ = s; }
  void set_send_result(hal::Status s) { send_result_ = s; }
  std::span<const hal::CanFilter> filters() const { return {filters_.data(), filter_count_}; }
  int restart_calls() const { return restart_calls_; }
  // Frames sent so far, the i-th of them (if among the last 64) and the last.
  uint32_t sent_count() const { return counters_.tx_frames; }
  const hal::CanFrame& sent(uint32_t i) const { return sent_[i % sent_.size()]; }
  const hal::CanFrame& last() const { return last_; }
  // The last frame sent with identifier `id`, if among the last 64 sent.
  bool last_with_id(uint32_t id, hal::CanFrame& out) const {
    const uint32_t n = counters_.tx_frames < sent_.size() ? counters_.tx_frames
                                                          : static_cast<uint32_t>(sent_.size());
    for (uint32_t k = 1; k <= n; ++k) {
      const auto& f = sent_[(counters_.tx_frames - k) % sent_.size()];
      if (f.id == id) {
        out = f;
        return true;
      }
    }
    return false;
  }

 private:
  hal::CanCounters counters_{};
  hal::CanFrame last_{};
  std::array<hal::CanFrame, 64> sent_{};
  std::array<hal::CanFrame, 16> rx_{};
  uint32_t rx_head_ = 0;
  uint32_t rx_tail_ = 0;
  std::array<hal::CanFilter, 8> filters_{};
  std::size_t filter_count_ = 0;
  hal::CanState state_ = hal::CanState::error_active;
  hal::Status send_result_ = hal::Status::ok;
  int restart_calls_ = 0;
};

}  // namespace hrg::fakes
