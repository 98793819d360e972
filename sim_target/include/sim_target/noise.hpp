// SPDX-License-Identifier: MIT
#pragma once

// Deterministic Gaussian noise: xoshiro256** seeded by splitmix64, and a
// ziggurat written out (Marsaglia and Tsang 2000, in Doornik's 2005 form with
// 128 layers), so a seed gives the same bits with every standard library
// (std::normal_distribution is implementation-defined).
//
// Why a ziggurat: the simulated board draws two normals per 100 kHz sample;
// Box-Muller costs a log and a sincos per pair, the ziggurat one 64-bit draw,
// a multiply and a compare for 98.8 % of the normals (the wedges and the tail
// beyond r = 3.4426 take an exp or a log). The distribution is exactly the
// normal one: the layers are accepted or rejected against the density itself.
// One draw feeds both the layer (its low 7 bits) and the abscissa (its top 52
// bits), which do not overlap.
//
// Drawn in blocks of kBlock, in three passes that each run as a tight loop:
// (1) kBlock 64-bit draws from kLanes independent xoshiro256** streams
// stepped side by side (the streams' states are struct-of-arrays, so the
// compiler steps them in vector registers); (2) the rectangle test of every
// draw; (3) the 1.2 % outside their rectangle finish the ziggurat from that
// draw (wedge or tail, retries) with uniforms from a further, scalar
// stream. Each normal is still one run of the ziggurat on independent
// uniforms, so the distribution is the normal one (tested: moments, tails,
// histogram, correlation at lags 1-8 in test_noise.cpp). normal() and fill()
// hand the buffer out in turn, so block boundaries and call patterns do not
// change bits.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace hrg::sim::detail {

class Gaussian {
 public:
  explicit Gaussian(uint64_t seed = 1) { reseed(seed); }

  void reseed(uint64_t seed) {
    pos_ = kBlock;  // the buffer is refilled from the new state
    for (auto& word : lanes_)
      for (auto& lane : word)
        lane = splitmix(seed);
    for (auto& word : s_)
      word = splitmix(seed);
  }

  // Uniform in (0, 1), from the scalar stream.
  double uniform() { return to_unit(next()); }

  double normal() {
    if (pos_ == kBlock) refill();
    return buf_[pos_++];
  }

  // n normals into out, in the order normal() would give them.
  void fill(double* out, std::size_t n) {
    while (n > 0) {
      if (pos_ == kBlock) refill();
      const std::size_t take = std::min(n, kBlock - pos_);
      std::copy_n(buf_.data() + pos_, take, out);
      pos_ += take;
      out += take;
      n -= take;
    }
  }

 private:
  static constexpr std::size_t kBlock = 256;  // normals per refill
  static constexpr std::size_t kLanes = 4;    // xoshiro streams stepped side by side
  static constexpr std::size_t kLayers = 128;
  static constexpr double kTailStart = 3.442619855899;       // r: where the tail begins
  static constexpr double kLayerArea = 9.91256303526217e-3;  // area of each layer
  static_assert(kBlock % kLanes == 0);

  // x[i]: right edge of layer i's rectangle (x[0] = V / f(r), the base layer
  // with the tail folded in; x[128] = 0); ratio[i] = x[i+1] / x[i].
  struct Layers {
    std::array<double, kLayers + 1> x{};
    std::array<double, kLayers> ratio{};
    Layers() {
      double f = std::exp(-0.5 * kTailStart * kTailStart);
      x[0] = kLayerArea / f;
      x[1] = kTailStart;
      x[kLayers] = 0.0;
      for (std::size_t i = 2; i < kLayers; ++i) {
        x[i] = std::sqrt(-2.0 * std::log(kLayerArea / x[i - 1] + f));
        f = std::exp(-0.5 * x[i] * x[i]);
      }
      for (std::size_t i = 0; i < kLayers; ++i)
        ratio[i] = x[i + 1] / x[i];
    }
  };
  static const Layers& layers() {
    static const Layers z;
    return z;
  }

  void refill() {
    const Layers& z = layers();
    draw_raw();
    std::size_t outside = 0;
    for (std::size_t k = 0; k < kBlock; ++k) {
      const uint64_t r = raw_[k];
      const double u = signed_unit(r);
      const auto i = static_cast<std::size_t>(r & (kLayers - 1));
      buf_[k] = u * z.x[i];
      outside_[outside] = static_cast<uint16_t>(k);
      outside += std::fabs(u) < z.ratio[i] ? 0 : 1;  // inside the layer's rectangle: done
    }
    for (std::size_t j = 0; j < outside; ++j) {
      const std::size_t k = outside_[j];
      buf_[k] = finish(z, raw_[k]);
    }
    pos_ = 0;
  }

  // Pass 1: the lanes' next kBlock / kLanes outputs each, interleaved.
  void draw_raw() {
    // The state in locals: the compiler need not assume raw_ aliases it.
    uint64_t s0[kLanes], s1[kLanes], s2[kLanes], s3[kLanes];
    for (std::size_t l = 0; l < kLanes; ++l) {
      s0[l] = lanes_[0][l];
      s1[l] = lanes_[1][l];
      s2[l] = lanes_[2][l];
      s3[l] = lanes_[3][l];
    }
    for (std::size_t k = 0; k < kBlock; k += kLanes) {
      for (std::size_t l = 0; l < kLanes; ++l) {
        const uint64_t a = rotl((s1[l] << 2) + s1[l], 7);  // s1 * 5, as shifts for the vector unit
        raw_[k + l] = (a << 3) + a;                        // * 9
        const uint64_t t = s1[l] << 17;
        s2[l] ^= s0[l];
        s3[l] ^= s1[l];
        s1[l] ^= s2[l];
        s0[l] ^= s3[l];
        s2[l] ^= t;
        s3[l] = rotl(s3[l], 45);
      }
    }
    for (std::size_t l = 0; l < kLanes; ++l) {
      lanes_[0][l] = s0[l];
      lanes_[1][l] = s1[l];
      lanes_[2][l] = s2[l];
      lanes_[3][l] = s3[l];
    }
  }

  // The ziggurat from a draw r that fell outside its layer's rectangle.
  double finish(const Layers& z, uint64_t r) {
    for (;;) {
      const double u = signed_unit(r);
      const auto i = static_cast<std::size_t>(r & (kLayers - 1));
      if (std::fabs(u) < z.ratio[i]) return u * z.x[i];  // a retry inside its rectangle
      if (i == 0) return tail(u < 0.0);
      // The wedge between the rectangle and the density: accept against f itself.
      const double x = u * z.x[i];
      const double f0 = std::exp(-0.5 * (z.x[i] * z.x[i] - x * x));
      const double f1 = std::exp(-0.5 * (z.x[i + 1] * z.x[i + 1] - x * x));
      if (f1 + uniform() * (f0 - f1) < 1.0) return x;
      r = next();
    }
  }

  // Marsaglia's tail beyond r: exact, by rejection from an exponential.
  double tail(bool negative) {
    double x = 0.0;
    double y = 0.0;
    do {
      x = std::log(uniform()) / kTailStart;
      y = std::log(uniform());
    } while (-2.0 * y < x * x);
    return negative ? x - kTailStart : kTailStart - x;
  }

  static uint64_t splitmix(uint64_t& seed) {
    seed += 0x9E3779B97F4A7C15ull;
    uint64_t z = seed;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // (-1, 1) from the top 52 bits, symmetric, never 0 or +-1: the bits as the
  // mantissa of a double in [2, 4), minus 3, plus half a step (all exact).
  static double signed_unit(uint64_t r) {
    const double d = std::bit_cast<double>((r >> 12) | 0x4000000000000000ull);
    return (d - 3.0) + 0x1.0p-52;
  }
  static double to_unit(uint64_t r) { return (static_cast<double>(r >> 11) + 0.5) * 0x1.0p-53; }
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t next() {  // the scalar stream (wedges, tails, retries)
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

  uint64_t lanes_[4][kLanes]{};  // state word w of lane l at [w][l]
  uint64_t s_[4]{};
  std::array<uint64_t, kBlock> raw_{};
  std::array<uint16_t, kBlock> outside_{};
  std::array<double, kBlock> buf_{};
  std::size_t pos_ = kBlock;
};

}  // namespace hrg::sim::detail
