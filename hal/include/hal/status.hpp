// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>

namespace hrg::hal {

// Outcome of every HAL call. Retryable outcomes leave the peripheral usable and
// the same call may succeed later; fatal outcomes mean the peripheral (or the
// request) is unusable until the caller changes something.
enum class Status : uint8_t {
  ok = 0,
  // Retryable.
  would_block,  // nothing to read / no room to write right now
  busy,         // peripheral is in use or restarting
  timeout,      // a deadline passed before the operation completed
  bus_off,      // CAN controller is bus-off; restart() then retry
  // Fatal.
  invalid_argument,  // the request itself is wrong (size, range, id)
  io_error,          // the device reported a hardware or driver error
  not_supported,     // the target does not implement this operation
  closed,            // the device was never opened or has gone away
};

constexpr bool is_retryable(Status s) {
  return s == Status::would_block || s == Status::busy || s == Status::timeout ||
         s == Status::bus_off;
}

constexpr bool is_fatal(Status s) { return s != Status::ok && !is_retryable(s); }

constexpr const char* to_string(Status s) {
  switch (s) {
    case Status::ok: return "ok";
    case Status::would_block: return "would_block";
    case Status::busy: return "busy";
    case Status::timeout: return "timeout";
    case Status::bus_off: return "bus_off";
    case Status::invalid_argument: return "invalid_argument";
    case Status::io_error: return "io_error";
    case Status::not_supported: return "not_supported";
    case Status::closed: return "closed";
  }
  return "unknown";
}

// Drivers own hardware; copying one would alias it.
class NonCopyable {
 public:
  NonCopyable() = default;
  NonCopyable(const NonCopyable&) = delete;
  NonCopyable& operator=(const NonCopyable&) = delete;

 protected:
  ~NonCopyable() = default;
};

}  // namespace hrg::hal
