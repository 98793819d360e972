// SPDX-License-Identifier: MIT
#pragma once

// Deterministic Gaussian noise: xoshiro256** seeded by splitmix64, and the
// Box-Muller transform written out, so a seed gives the same bits with every
// standard library (std::normal_distribution is implementation-defined).

#include <cmath>
#include <cstdint>
#include <numbers>

namespace hrg::sim::detail {

class Gaussian {
 public:
  explicit Gaussian(uint64_t seed = 1) { reseed(seed); }

  void reseed(uint64_t seed) {
    for (auto& s : s_) {
      seed += 0x9E3779B97F4A7C15ull;
      uint64_t z = seed;
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      s_[&s - s_] = z ^ (z >> 31);
    }
    has_spare_ = false;
  }

  // Uniform in (0, 1).
  double uniform() {
    const uint64_t r = next();
    return (static_cast<double>(r >> 11) + 0.5) * 0x1.0p-53;
  }

  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(uniform()));
    const double a = 2.0 * std::numbers::pi * uniform();
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t next() {
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  uint64_t s_[4]{};
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace hrg::sim::detail
