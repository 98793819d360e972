// SPDX-License-Identifier: MIT
// Rate series of known power-law noise for the characterization tests.
#pragma once

#include <complex>
#include <cstddef>
#include <random>
#include <vector>

#include <unsupported/Eigen/FFT>

namespace hrg::testing {

inline std::vector<double> white_series(std::size_t n, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> y(n);
  for (double& v : y)
    v = g(rng);
  return y;
}

// Random walk of the rate: increments of standard deviation step per sample.
inline std::vector<double> random_walk_series(std::size_t n, double step, std::uint64_t seed) {
  std::vector<double> y = white_series(n, step, seed);
  for (std::size_t i = 1; i < n; ++i)
    y[i] += y[i - 1];
  return y;
}

// Kasdin's discrete 1/f^alpha_f noise (N. J. Kasdin, Proc. IEEE 83(5), 1995):
// white innovations of variance q through the filter (1 - z^-1)^(-alpha_f/2),
// whose impulse response is h0 = 1, hk = h(k-1) (k - 1 + alpha_f/2) / k. Its
// one-sided density is 2 q tau0 / |2 sin(pi f tau0)|^alpha_f, so alpha_f = 1
// (flicker rate) has S(f) -> q / (pi f) at low f: IEEE 952's B^2 = q.
inline std::vector<double> kasdin_series(std::size_t n, double alpha_f, double q,
                                         std::uint64_t seed) {
  const std::vector<double> w = white_series(n, std::sqrt(q), seed);
  const std::size_t nfft = 2 * n;  // zero padding: linear, not circular, convolution
  std::vector<double> h(nfft, 0.0), wp(nfft, 0.0);
  h[0] = 1.0;
  for (std::size_t k = 1; k < n; ++k)
    h[k] = h[k - 1] * (static_cast<double>(k) - 1.0 + 0.5 * alpha_f) / static_cast<double>(k);
  std::copy(w.begin(), w.end(), wp.begin());
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> hf, wf;
  fft.fwd(hf, h);
  fft.fwd(wf, wp);
  for (std::size_t i = 0; i < hf.size(); ++i)
    hf[i] *= wf[i];
  std::vector<double> y;
  fft.inv(y, hf);
  y.resize(n);
  return y;
}

}  // namespace hrg::testing
