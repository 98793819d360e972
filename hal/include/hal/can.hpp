// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "hal/status.hpp"

namespace hrg::hal {

// Classic CAN frame (11-bit or 29-bit identifier, up to 8 data bytes).
struct CanFrame {
  uint32_t id = 0;
  bool extended = false;
  uint8_t len = 0;
  std::array<uint8_t, 8> data{};
};

// Accept a frame when (frame.id & mask) == (id & mask).
struct CanFilter {
  uint32_t id = 0;
  uint32_t mask = 0;
};

enum class CanState : uint8_t { error_active, error_warning, error_passive, bus_off };

struct CanCounters {
  uint32_t tx_frames = 0;
  uint32_t rx_frames = 0;
  uint32_t tx_queue_full = 0;  // send() refused because the queue was full
  uint32_t error_frames = 0;
  uint32_t bus_off_events = 0;
  uint32_t restarts = 0;
};

// Never blocks: the executive calls it from its frames.
class CanBus : NonCopyable {
 public:
  virtual ~CanBus() = default;
  // would_block when the TX queue is full (counted), bus_off while bus-off.
  virtual Status send(const CanFrame& frame) = 0;
  // would_block when nothing is waiting.
  virtual Status receive(CanFrame& frame) = 0;
  // Replaces the receive filters; an empty list accepts everything.
  virtual Status set_filters(std::span<const CanFilter> filters) = 0;
  virtual CanState state() const = 0;
  // Leaves bus-off (the controller's restart), counted in restarts.
  virtual Status restart() = 0;
  virtual CanCounters counters() const = 0;
};

}  // namespace hrg::hal
