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
// beyond r = 3.4426 take more: a wedge's test against the density is decided
// by the density's tangent and chord for 99.4 % of the wedge draws, by an exp
// for the rest; the tail takes two logs). The distribution is exactly the
// normal one: the layers are accepted or rejected against the density itself.
// One draw feeds both the layer (its low 7 bits) and the abscissa (its top 53
// bits), which do not overlap.
//
// The rectangle test is made on integers, with the same outcome and the same
// normal: the abscissa u = 2 ((j + 1/2) 2^-53) - 1 (j the top 53 bits) is
// m 2^-53 for the integer m of abscissa_units() (which follows the one
// rounding in it), so |u| < ratio[i] is |m| < ceil(ratio[i] 2^53)
// (Layers::inside()) and u x[i] is m (x[i] 2^-53), the same product. The board's loop is bound by
// its floating-point work (the resonator's step): this leaves the draws to the integer units but
// for one conversion and one product.
//
// normal() and fill() draw one normal at a time; Stream gives the same
// sequence with the generator's state in registers over a loop.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

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
      s = z ^ (z >> 31);
    }
  }

  // Uniform in (0, 1).
  double uniform() { return to_unit(next_bits()); }

  double normal() { return draw(*z_); }

 private:
  struct Layers;

 public:
  // The same sequence as normal(), for one tight loop that interleaves the
  // draws with other work (one sample at a time): the generator's state is
  // copied into the stream, where it can live in registers, so that its
  // chain overlaps that work's. The ziggurat's rectangle test is inline,
  // the wedges and the tail (1.2 % of the draws) go through the generator
  // itself. commit() hands
  // the state back; the generator must not be used before it.
  class Stream {
   public:
    explicit Stream(Gaussian& g)
        : g_(g), z_(g.z_), s0_(g.s_[0]), s1_(g.s_[1]), s2_(g.s_[2]), s3_(g.s_[3]) {}
    [[gnu::always_inline]] double normal() {
      const uint64_t r = rotl(s1_ * 5, 7) * 9;  // xoshiro256**, as next_bits()
      const uint64_t t = s1_ << 17;
      s2_ ^= s0_;
      s3_ ^= s1_;
      s1_ ^= s2_;
      s0_ ^= s3_;
      s2_ ^= t;
      s3_ = rotl(s3_, 45);
      const int64_t m = abscissa_units(r);  // as in draw()
      const auto i = static_cast<std::size_t>(r & (kLayers - 1));
      if (z_->inside(m, i)) [[likely]]
        return static_cast<double>(m) * z_->x_unit[i];
      commit();
      const double v = g_.finish(m, i);
      s0_ = g_.s_[0];
      s1_ = g_.s_[1];
      s2_ = g_.s_[2];
      s3_ = g_.s_[3];
      return v;
    }
    void commit() {
      g_.s_[0] = s0_;
      g_.s_[1] = s1_;
      g_.s_[2] = s2_;
      g_.s_[3] = s3_;
    }

   private:
    Gaussian& g_;
    const Layers* z_;
    uint64_t s0_, s1_, s2_, s3_;
  };

  // The ziggurat's layer edges x[i] (i = 0..128) and the wedge squeeze of
  // layer i (1..127): whether y < exp(minus_v), or none where it leaves
  // that to the exp (for tests).
  static double layer_edge(std::size_t i) { return layers().x[i]; }
  static std::optional<bool> wedge_squeeze(std::size_t i, double y, double minus_v) {
    return squeeze(layers(), i, y, minus_v);
  }

  // n normals into out, in the order normal() would give them.
  void fill(double* out, std::size_t n) {
    const Layers& z = *z_;
    for (std::size_t k = 0; k < n; ++k)
      out[k] = draw(z);
  }

 private:
  static constexpr std::size_t kLayers = 128;
  static constexpr double kTailStart = 3.442619855899;       // r: where the tail begins
  static constexpr double kLayerArea = 9.91256303526217e-3;  // area of each layer

  // x[i]: right edge of layer i's rectangle (x[0] = V / f(r), the base layer
  // with the tail folded in; x[128] = 0); ratio[i] = x[i+1] / x[i];
  // x_unit[i] = x[i] 2^-53 (a power of two: exact). With T = ceil(ratio[i]
  // 2^53), the least |m| outside (exact: ratio[i] 2^53 is a double,
  // integral or not), |m| < T is m + T - 1 < 2 T - 1 taken unsigned (no
  // branch or absolute value): offset[i] = T - 1, span[i] = 2 T - 1, and 0
  // for the top layer's T = 0 (ratio 0: always outside).
  struct Layers {
    std::array<double, kLayers + 1> x{};
    std::array<double, kLayers> ratio{};
    std::array<double, kLayers> x_unit{};
    std::array<uint64_t, kLayers> offset{};
    std::array<uint64_t, kLayers> span{};
    std::array<double, kLayers + 1> density{};  // exp(-x[i]^2 / 2) at each edge
    // The wedge's squeeze (see outside()): in v = x^2 / 2, exp(-v) lies
    // between its tangent at the layer's middle, below_0 + below_1 (-v),
    // and its chord over the layer, above_0 + above_1 (-v).
    std::array<double, kLayers> below_0{};
    std::array<double, kLayers> below_1{};
    std::array<double, kLayers> above_0{};
    std::array<double, kLayers> above_1{};
    bool inside(int64_t m, std::size_t i) const {
      return static_cast<uint64_t>(m) + offset[i] < span[i];
    }
    Layers() {
      double f = std::exp(-0.5 * kTailStart * kTailStart);
      x[0] = kLayerArea / f;
      x[1] = kTailStart;
      x[kLayers] = 0.0;
      for (std::size_t i = 2; i < kLayers; ++i) {
        x[i] = std::sqrt(-2.0 * std::log(kLayerArea / x[i - 1] + f));
        f = std::exp(-0.5 * x[i] * x[i]);
      }
      for (std::size_t i = 0; i < kLayers; ++i) {
        ratio[i] = x[i + 1] / x[i];
        const auto t = static_cast<uint64_t>(std::ceil(ratio[i] * 0x1p53));
        offset[i] = t - 1;
        span[i] = t > 0 ? 2 * t - 1 : 0;
        x_unit[i] = x[i] * 0x1p-53;
      }
      for (std::size_t i = 0; i <= kLayers; ++i)
        density[i] = std::exp(-0.5 * x[i] * x[i]);
      for (std::size_t i = 1; i < kLayers; ++i) {  // layer 0 has the tail instead
        const double v_in = 0.5 * x[i + 1] * x[i + 1];
        const double v_out = 0.5 * x[i] * x[i];
        const double v_mid = 0.5 * (v_in + v_out);
        const double f_mid = std::exp(-v_mid);
        below_0[i] = f_mid * (1.0 + v_mid);  // f_mid (1 - (v - v_mid))
        below_1[i] = f_mid;
        const double slope = (density[i] - density[i + 1]) / (v_out - v_in);
        above_0[i] = density[i + 1] - slope * v_in;  // density[i + 1] + slope (v - v_in)
        above_1[i] = -slope;
      }
    }
  };
  static const Layers& layers() {
    static const Layers z;
    return z;
  }

  // One normal by the ziggurat.
  double draw(const Layers& z) {
    for (;;) {
      const uint64_t r = next_bits();
      const int64_t m = abscissa_units(r);  // u = m 2^-53 in [-1, 1]
      const auto i = static_cast<std::size_t>(r & (kLayers - 1));
      if (z.inside(m, i)) return static_cast<double>(m) * z.x_unit[i];  // in the rectangle
      if (const auto v = outside(z, m, i)) return *v;
    }
  }
  // A draw (u = m 2^-53, layer i) outside its layer's rectangle: the tail
  // (layer 0), or the wedge between the rectangle and the density, accepted
  // against the density itself: f(x[i+1]) + U (f(x[i]) - f(x[i+1])) <
  // f(x), with f(x) = exp(-x^2/2). None when rejected.
  std::optional<double> outside(const Layers& z, int64_t m, std::size_t i) {
    const double u = static_cast<double>(m) * 0x1p-53;
    if (i == 0) return tail(u < 0.0);
    const double x = u * z.x[i];
    const double f0 = z.density[i];
    const double f1 = z.density[i + 1];
    const double y = f1 + uniform() * (f0 - f1);
    const double minus_v = -0.5 * x * x;
    const std::optional<bool> below = squeeze(z, i, y, minus_v);
    if (below.has_value() ? *below : y < std::exp(minus_v)) return x;
    return std::nullopt;
  }
  // Whether y < exp(minus_v) (the wedge's test), decided without the exp
  // where y is clear of the density's bounds by kSqueezeMargin; none where
  // it is not (a few per cent of the wedges). exp(-v) is convex in v, so
  // the tangent is below it everywhere and the chord above it over the
  // layer (v from x[i+1]^2 / 2 to x[i]^2 / 2; a draw's x is within a
  // rounding of that span, which moves the chord by ~1e-16). The libm exp
  // is within an ulp (2.2e-16 at most here, f <= 1) and the bounds within a
  // few ulps of their exact values: a margin of 1e-12 leaves the outcome
  // the exp comparison's, draw for draw.
  static std::optional<bool> squeeze(const Layers& z, std::size_t i, double y, double minus_v) {
    constexpr double kSqueezeMargin = 1e-12;
    if (y < z.below_0[i] + z.below_1[i] * minus_v - kSqueezeMargin) return true;
    if (y > z.above_0[i] + z.above_1[i] * minus_v + kSqueezeMargin) return false;
    return std::nullopt;
  }
  // draw() after a draw fell outside its rectangle: outside(), then draw()
  // again if rejected (the same sequence).
  [[gnu::noinline]] double finish(int64_t m, std::size_t i) {
    if (const auto v = outside(*z_, m, i)) return *v;
    return draw(*z_);
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

  static double to_unit(uint64_t r) { return (static_cast<double>(r >> 11) + 0.5) * 0x1.0p-53; }

 public:
  // 2 to_unit(r) - 1 in units of 2^-53, exactly: with j = r >> 11, j + 1/2
  // is exact below 2^52 (m = 2 j + 1 - 2^53) and rounds to the even
  // neighbour above it (m = 2 (j + (j & 1)) - 2^53); the product and the
  // subtraction after it are exact. |m| <= 2^53, so double(m) is exact too.
  static int64_t abscissa_units(uint64_t r) {
    const uint64_t j = r >> 11;
    const uint64_t high = j >> 52;         // 1 when j >= 2^52
    const uint64_t even = j + (j & high);  // j + 1/2 rounded, above 2^52 (less 1/2)
    return static_cast<int64_t>(2 * even + 1 - high) - (int64_t{1} << 53);
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t next_bits() {
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
  const Layers* z_ = &layers();
};

}  // namespace hrg::sim::detail
