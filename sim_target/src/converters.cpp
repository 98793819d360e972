// SPDX-License-Identifier: MIT
#include "sim_target/converters.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hrg::sim {

namespace {
uint32_t checked_bits(uint32_t bits) {
  if (bits < 2 || bits > 32) throw std::invalid_argument("converter bits must be in [2, 32]");
  return bits;
}
}  // namespace

AdcQuantizer::AdcQuantizer(const AdcConfig& c)
    : bits_(checked_bits(c.bits)),
      full_scale_v_(c.full_scale_v),
      lsb_v_(c.full_scale_v / std::ldexp(1.0, static_cast<int>(c.bits) - 1)),
      inv_lsb_(1.0 / lsb_v_),
      inverse_exact_(std::isnormal(lsb_v_) && std::isnormal(inv_lsb_)),
      code_max_((int64_t{1} << (c.bits - 1)) - 1) {}

double AdcQuantizer::to_volts(hal::q31_t word) const {
  return static_cast<double>(word) * 0x1.0p-31 * full_scale_v_;
}

DacQuantizer::DacQuantizer(const DacConfig& c)
    : bits_(checked_bits(c.bits)),
      full_scale_v_(c.full_scale_v),
      code_max_((int64_t{1} << (c.bits - 1)) - 1),
      volts_per_code_(c.full_scale_v / static_cast<double>(code_max_ + 1)) {}

hal::q31_t DacQuantizer::word_for(double v) const {
  const double code =
      std::clamp(std::nearbyint(v / full_scale_v_ * static_cast<double>(code_max_ + 1)),
                 static_cast<double>(-code_max_ - 1), static_cast<double>(code_max_));
  return static_cast<hal::q31_t>(static_cast<int64_t>(code) * (int64_t{1} << (32 - bits_)));
}

}  // namespace hrg::sim
