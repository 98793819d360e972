// SPDX-License-Identifier: MIT
#include "firmware/can/signal.hpp"

namespace hrg::fw::can {

namespace {

// Round half away from zero without <cmath> (freestanding builds).
int64_t round_to_int(double v) {
  return v >= 0.0 ? static_cast<int64_t>(v + 0.5) : -static_cast<int64_t>(-v + 0.5);
}

}  // namespace

int64_t to_raw(const SignalDef& s, double physical) {
  double v = physical;
  if (v != v) v = (s.min <= 0.0 && s.max >= 0.0) ? 0.0 : (s.min > 0.0 ? s.min : s.max);
  if (v < s.min) v = s.min;
  if (v > s.max) v = s.max;
  int64_t raw = round_to_int((v - s.offset) / s.factor);
  if (raw < raw_min(s)) raw = raw_min(s);
  if (raw > raw_max(s)) raw = raw_max(s);
  return raw;
}

double to_physical(const SignalDef& s, int64_t raw) {
  return static_cast<double>(raw) * s.factor + s.offset;
}

void encode_signal(const SignalDef& s, double physical, hal::CanFrame& f) {
  put_bits(f, s.start_bit, s.length, static_cast<uint64_t>(to_raw(s, physical)));
}

int64_t decode_raw(const SignalDef& s, const hal::CanFrame& f) {
  const uint64_t raw = get_bits(f, s.start_bit, s.length);
  if (s.is_signed && ((raw >> (s.length - 1)) & 1u)) {
    return static_cast<int64_t>(raw) - (int64_t{1} << s.length);
  }
  return static_cast<int64_t>(raw);
}

double decode_signal(const SignalDef& s, const hal::CanFrame& f) {
  return to_physical(s, decode_raw(s, f));
}

}  // namespace hrg::fw::can
