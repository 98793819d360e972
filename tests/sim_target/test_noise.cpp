// SPDX-License-Identifier: MIT
// The simulated board's Gaussian (xoshiro256** + ziggurat): 1e7 draws against
// the normal distribution's moments, tail probabilities and histogram, and no
// correlation from one draw to the next eight (the lanes of the generator). Bounds are 5 standard
// errors of each statistic for N draws (the seed is fixed, so the test is deterministic).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "sim_target/noise.hpp"

#include "support/cpputest.hpp"

namespace {
constexpr std::size_t kN = 10'000'000;

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }
}  // namespace

TEST_GROUP(Gaussian){};

TEST(Gaussian, MomentsTailsAndHistogramAreTheNormalOnes) {
  hrg::sim::detail::Gaussian g(20240531);
  std::vector<double> x(kN);
  g.fill(x.data(), kN);
  const double n = static_cast<double>(kN);
  double m1 = 0, m2 = 0, m4 = 0;
  double lag[9] = {};  // lags 1-8
  std::size_t beyond2 = 0, beyond3 = 0, beyond4 = 0;
  constexpr int kBins = 40;  // width 0.25 over [-5, 5)
  std::vector<double> hist(kBins, 0.0);
  for (std::size_t i = 0; i < kN; ++i) {
    const double v = x[i];
    m1 += v;
    m2 += v * v;
    m4 += v * v * v * v;
    for (std::size_t l = 1; l <= 8 && l <= i; ++l)
      lag[l] += v * x[i - l];
    const double a = std::fabs(v);
    beyond2 += a > 2.0;
    beyond3 += a > 3.0;
    beyond4 += a > 4.0;
    const int b = static_cast<int>(std::floor((v + 5.0) / 0.25));
    if (b >= 0 && b < kBins) hist[static_cast<std::size_t>(b)] += 1.0;
  }
  m1 /= n;
  m2 /= n;
  m4 /= n;

  CHECK(std::fabs(m1) < 5.0 / std::sqrt(n));
  CHECK(std::fabs(m2 - 1.0) < 5.0 * std::sqrt(2.0 / n));
  CHECK(std::fabs(m4 - 3.0) < 5.0 * std::sqrt(96.0 / n));
  for (std::size_t l = 1; l <= 8; ++l)
    CHECK(std::fabs(lag[l] / (n - static_cast<double>(l))) < 5.0 / std::sqrt(n));
  const double tails[3] = {2.0, 3.0, 4.0};
  const std::size_t counts[3] = {beyond2, beyond3, beyond4};
  for (int k = 0; k < 3; ++k) {
    const double p = 2.0 * normal_cdf(-tails[k]);  // 4.55e-2, 2.70e-3, 6.33e-5
    const double c = static_cast<double>(counts[k]);
    CHECK(std::fabs(c - n * p) < 5.0 * std::sqrt(n * p * (1.0 - p)));
  }
  // Chi-square over the bins with an expectation of at least 50 draws:
  // mean = degrees of freedom, 5 standard deviations = 5 sqrt(2 dof).
  double chi2 = 0.0;
  int dof = -1;
  for (int b = 0; b < kBins; ++b) {
    const double lo = -5.0 + 0.25 * b;
    const double expect = n * (normal_cdf(lo + 0.25) - normal_cdf(lo));
    if (expect < 50.0) continue;
    const double d = hist[static_cast<std::size_t>(b)] - expect;
    chi2 += d * d / expect;
    ++dof;
  }
  CHECK(dof > 30);
  CHECK(chi2 < dof + 5.0 * std::sqrt(2.0 * dof));
}

TEST(Gaussian, StreamGivesTheSameDrawsAsNormalInTurn) {
  // 1e5 draws (about 1200 wedges or tail draws, which go back through the
  // generator), with normal() and fill() between the streams.
  hrg::sim::detail::Gaussian a(11);
  hrg::sim::detail::Gaussian b(11);
  double block[300];
  std::size_t drawn = 0;
  for (int round = 0; round < 330; ++round) {
    CHECK_EQUAL(b.normal(), a.normal());
    a.fill(block, 17);
    for (std::size_t i = 0; i < 17; ++i)
      CHECK_EQUAL(b.normal(), block[i]);
    hrg::sim::detail::Gaussian::Stream s(a);
    for (std::size_t i = 0; i < 300; ++i)
      block[i] = s.normal();
    s.commit();
    for (double v : block)
      CHECK_EQUAL(b.normal(), v);
    drawn += 318;
  }
  CHECK(drawn > 100'000);
}

TEST(Gaussian, FillGivesTheSameDrawsAsNormalInTurn) {
  hrg::sim::detail::Gaussian a(7);
  hrg::sim::detail::Gaussian b(7);
  double block[1000];
  a.fill(block, 1000);
  for (double v : block)
    CHECK_EQUAL(b.normal(), v);
}

TEST(Gaussian, TheIntegerAbscissaIsTheFloatingPointOne) {
  // The ziggurat's abscissa u = 2 ((j + 1/2) 2^-53) - 1 (j the draw's top
  // 53 bits, j + 1/2 rounded to even from 2^52 on) in units of 2^-53: equal
  // to u exactly, at the edges of both halves and for 1e6 draws; so the
  // integer rectangle test and product give the floating-point ones' bits.
  const auto u_of = [](uint64_t r) {
    const double t = (static_cast<double>(r >> 11) + 0.5) * 0x1.0p-53;
    return 2.0 * t - 1.0;
  };
  const auto check = [&](uint64_t r) {
    const int64_t m = hrg::sim::detail::Gaussian::abscissa_units(r);
    CHECK_EQUAL(u_of(r), static_cast<double>(m) * 0x1p-53);
  };
  const uint64_t edges[] = {0,
                            (uint64_t{1} << 11) - 1,
                            uint64_t{1} << 11,
                            ((uint64_t{1} << 52) - 1) << 11,
                            uint64_t{1} << 63,
                            (uint64_t{1} << 63) | (uint64_t{1} << 11),
                            (uint64_t{1} << 63) | (uint64_t{2} << 11),
                            ~uint64_t{0},
                            ~uint64_t{0} << 11};
  for (const uint64_t r : edges)
    check(r);
  // u = -1 + 2^-53, 0 (j = 2^52) and 1 (j = 2^53 - 1, rounded up) exactly.
  LONGS_EQUAL(1 - (int64_t{1} << 53), hrg::sim::detail::Gaussian::abscissa_units(0));
  LONGS_EQUAL(0, hrg::sim::detail::Gaussian::abscissa_units(uint64_t{1} << 63));
  LONGS_EQUAL(int64_t{1} << 53, hrg::sim::detail::Gaussian::abscissa_units(~uint64_t{0}));
  uint64_t x = 0x243F6A8885A308D3ull;  // splitmix64 over a fixed seed
  for (int k = 0; k < 1'000'000; ++k) {
    x += 0x9E3779B97F4A7C15ull;
    uint64_t z = x;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    check(z ^ (z >> 31));
  }
}

TEST(Gaussian, TheWedgeSqueezeDecidesAsTheExpDoes) {
  // The wedge test y < exp(-x^2/2) is decided without the exp where y is
  // clear of the tangent (below) or the chord (above) of exp(-v), v =
  // x^2 / 2. Over each layer's wedge rectangle (x uniform over [x[i+1],
  // x[i]], y over [f(x[i]), f(x[i+1])], as the ziggurat's wedge draws are),
  // and at y within a few ulps of the density: every decision is the exp
  // comparison's, and the share decided is the area outside the band
  // between the two bounds (integrated here), within 5 standard errors.
  using G = hrg::sim::detail::Gaussian;
  G g(314159);
  const auto f = [](double v) { return std::exp(-v); };
  constexpr int kPerLayer = 20'000;
  double decided = 0.0;
  double expected = 0.0;
  double variance = 0.0;
  for (std::size_t i = 1; i < 128; ++i) {
    const double a = G::layer_edge(i + 1);
    const double b = G::layer_edge(i);
    const double v_a = 0.5 * a * a;
    const double v_b = 0.5 * b * b;
    const double f_a = f(v_a);
    const double f_b = f(v_b);
    // The band's share of the rectangle: chord minus tangent (at the
    // middle of v), both clipped to [f_b, f_a], by the midpoint rule.
    const double v_m = 0.5 * (v_a + v_b);
    double band = 0.0;
    constexpr int kSteps = 2000;
    for (int k = 0; k < kSteps; ++k) {
      const double x = a + (k + 0.5) / kSteps * (b - a);
      const double v = 0.5 * x * x;
      const double chord = f_a + (f_b - f_a) * (v - v_a) / (v_b - v_a);
      const double tangent = std::max(f_b, f(v_m) * (1.0 - (v - v_m)));
      band += std::max(0.0, chord - tangent) / kSteps;
    }
    const double p = 1.0 - band / (f_a - f_b);
    expected += p * kPerLayer;
    variance += p * (1.0 - p) * kPerLayer;
    for (int k = 0; k < kPerLayer; ++k) {
      const double x = a + g.uniform() * (b - a);
      const double y = f_a + g.uniform() * (f_b - f_a);
      const double minus_v = -0.5 * x * x;
      const std::optional<bool> below = G::wedge_squeeze(i, y, minus_v);
      if (below.has_value()) {
        CHECK_EQUAL(y < std::exp(minus_v), *below);
        decided += 1.0;
      }
      // At the density itself, a few ulps either side: decided right or not at all.
      const double e = std::exp(minus_v);
      for (const double y_near :
           {e, std::nextafter(e, 0.0), std::nextafter(e, 2.0), e * (1 - 1e-14), e * (1 + 1e-14)}) {
        const std::optional<bool> near = G::wedge_squeeze(i, y_near, minus_v);
        if (near.has_value()) CHECK_EQUAL(y_near < e, *near);
      }
    }
  }
  CHECK(expected > 0.99 * 127 * kPerLayer);  // the band is thin: the exp is rarely needed
  CHECK(std::fabs(decided - expected) < 5.0 * std::sqrt(variance));
}
