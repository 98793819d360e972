// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "hal/can.hpp"

namespace hrg::fw::can {

// A signal's part in a multiplexed message (DBC `M` and `mN`): the
// multiplexor selects the page; a multiplexed signal is in the frame only
// when the multiplexor's raw value is its `mux_value`; a plain one always is.
enum class MuxRole : uint8_t { plain, multiplexor, multiplexed };

// One signal of a CAN message, as in the DBC: little-endian (Intel) bit layout,
// `start_bit` is the LSB position (bit i lives in byte i/8, bit i%8).
// physical = raw * factor + offset; [min, max] is the valid physical range.
struct SignalDef {
  const char* name;
  uint8_t start_bit;
  uint8_t length;  // 1..32
  bool is_signed;  // two's complement raw value
  double factor;
  double offset;
  double min;
  double max;
  const char* unit;
  MuxRole mux = MuxRole::plain;
  uint8_t mux_value = 0;  // the page, for a multiplexed signal
};

// True when signal `s` is in a frame whose multiplexor reads `page` (always
// for a plain signal or the multiplexor itself).
constexpr bool on_page(const SignalDef& s, unsigned page) {
  return s.mux != MuxRole::multiplexed || s.mux_value == page;
}

// One message: identifier (11-bit), data length and signals. `default_rate_hz`
// is the telemetry rate (0 for commands and replies, which are sent on event).
struct MessageDef {
  const char* name;
  uint32_t id;
  uint8_t dlc;
  uint16_t default_rate_hz;
  const char* sender;  // DBC node: "HRG" or "HOST"
  std::span<const SignalDef> signals;
};

// Raw bit field access. `start_bit + length` must be <= 64 (checked by callers'
// tables at compile time); the value is masked to `length` bits.
constexpr void put_bits(hal::CanFrame& f, unsigned start_bit, unsigned length, uint64_t raw) {
  for (unsigned i = 0; i < length; ++i) {
    const unsigned bit = start_bit + i;
    const auto mask = static_cast<uint8_t>(1u << (bit % 8));
    if ((raw >> i) & 1u) {
      f.data[bit / 8] = static_cast<uint8_t>(f.data[bit / 8] | mask);
    } else {
      f.data[bit / 8] = static_cast<uint8_t>(f.data[bit / 8] & ~mask);
    }
  }
}

constexpr uint64_t get_bits(const hal::CanFrame& f, unsigned start_bit, unsigned length) {
  uint64_t raw = 0;
  for (unsigned i = 0; i < length; ++i) {
    const unsigned bit = start_bit + i;
    raw |= static_cast<uint64_t>((f.data[bit / 8] >> (bit % 8)) & 1u) << i;
  }
  return raw;
}

// Raw integer limits of a signal's field.
constexpr int64_t raw_min(const SignalDef& s) {
  return s.is_signed ? -(int64_t{1} << (s.length - 1)) : 0;
}
constexpr int64_t raw_max(const SignalDef& s) {
  return s.is_signed ? (int64_t{1} << (s.length - 1)) - 1 : (int64_t{1} << s.length) - 1;
}

// Physical value -> raw, rounded to nearest, saturated to [min, max] (and to the
// field). NaN encodes as the value nearest to zero within [min, max].
int64_t to_raw(const SignalDef& s, double physical);
double to_physical(const SignalDef& s, int64_t raw);

// Writes a signal into the frame (saturating, see to_raw).
void encode_signal(const SignalDef& s, double physical, hal::CanFrame& f);
// Reads a signal (sign-extended when signed).
int64_t decode_raw(const SignalDef& s, const hal::CanFrame& f);
double decode_signal(const SignalDef& s, const hal::CanFrame& f);

// Worst-case bits on the wire for a classic CAN data frame with an 11-bit
// identifier and `dlc` bytes, including bit stuffing and the 3-bit interframe
// space: 47 + 8 dlc + floor((34 + 8 dlc - 1) / 4).
constexpr uint32_t worst_case_frame_bits(uint8_t dlc) {
  return 47u + 8u * dlc + (34u + 8u * dlc - 1u) / 4u;
}

}  // namespace hrg::fw::can
