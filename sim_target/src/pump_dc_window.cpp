// SPDX-License-Identifier: MIT
#include "sim_target/pump_dc_window.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

namespace hrg::sim {

PumpDcWindow pump_dc_window(double period_samples, int max_length) {
  PumpDcWindow w;
  w.length = std::clamp(static_cast<int>(std::lround(period_samples)), 1, max_length);
  // A whole period: the mean alone rejects the 2f line (a = m to the bit).
  if (std::abs(period_samples - w.length) <= 1e-9 * period_samples) return w;
  const double theta = 4.0 * std::numbers::pi / period_samples;
  std::complex<double> beta = 0.0;
  for (int j = 0; j < w.length; ++j)
    beta += std::polar(1.0, -theta * j);
  beta /= static_cast<double>(w.length);
  double best = 0.0;
  for (int k = 1; k <= 4; ++k) {
    if (std::abs(std::sin(k * theta)) > best) {
      best = std::abs(std::sin(k * theta));
      w.lag = k;
    }
  }
  const double s = std::sin(w.lag * theta);
  const double a = beta.real() + beta.imag() * std::cos(w.lag * theta) / s;
  const double b = beta.imag() / s;
  const double norm = 1.0 / (1.0 - a + b);
  w.whole = false;
  w.w_sum = norm / w.length;
  w.w_now = -a * norm;
  w.w_lag = b * norm;
  return w;
}

}  // namespace hrg::sim
