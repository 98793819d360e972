// SPDX-License-Identifier: MIT
#include "sim_target/sim_can.hpp"

namespace hrg::sim {

using hal::CanFrame;
using hal::Status;

void SimCan::configure(const CanConfig& c) {
  config_ = c;
  std::vector<CanFrame>().swap(tx_);
  std::vector<CanFrame>().swap(rx_);
  std::vector<CanFrame>().swap(sent_);
  std::vector<hal::CanFilter>().swap(filters_);
  state_ = hal::CanState::error_active;
  counters_ = {};
  tx_credit_ = 0.0;
}

Status SimCan::send(const CanFrame& frame) {
  if (frame.len > 8 || (!frame.extended && frame.id > 0x7FF) || frame.id > 0x1FFFFFFF) {
    return Status::invalid_argument;
  }
  if (state_ == hal::CanState::bus_off) return Status::bus_off;
  if (tx_.size() >= config_.tx_queue_frames) {
    ++counters_.tx_queue_full;
    return Status::would_block;
  }
  tx_.push_back(frame);
  return Status::ok;
}

Status SimCan::receive(CanFrame& frame) {
  if (rx_.empty()) return Status::would_block;
  frame = rx_.front();
  rx_.erase(rx_.begin());
  ++counters_.rx_frames;
  return Status::ok;
}

Status SimCan::set_filters(std::span<const hal::CanFilter> filters) {
  filters_.assign(filters.begin(), filters.end());
  return Status::ok;
}

Status SimCan::restart() {
  if (state_ != hal::CanState::bus_off) return Status::ok;
  state_ = hal::CanState::error_active;
  ++counters_.restarts;
  return Status::ok;
}

void SimCan::tick(double dt_s) {
  if (state_ == hal::CanState::bus_off) return;
  tx_credit_ += dt_s * 1000.0 * config_.tx_frames_per_ms;
  while (!tx_.empty() && tx_credit_ >= 1.0) {
    sent_.push_back(tx_.front());
    tx_.erase(tx_.begin());
    ++counters_.tx_frames;
    tx_credit_ -= 1.0;
  }
  if (tx_.empty() && tx_credit_ > 1.0) tx_credit_ = 1.0;  // an idle bus stores no credit
}

void SimCan::inject_rx(const CanFrame& frame) {
  bool accept = filters_.empty();
  for (const auto& f : filters_) {
    if ((frame.id & f.mask) == (f.id & f.mask)) accept = true;
  }
  if (accept) rx_.push_back(frame);
}

void SimCan::force_bus_off() {
  state_ = hal::CanState::bus_off;
  tx_.clear();
  ++counters_.bus_off_events;
  ++counters_.error_frames;
}

}  // namespace hrg::sim
