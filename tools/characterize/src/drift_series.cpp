// SPDX-License-Identifier: MIT
#include "characterize/drift_series.hpp"

#include <cmath>

#include "characterize/chi_square.hpp"

namespace hrg::characterize {

Repeatability bias_repeatability(std::span<const double> bias, double confidence) {
  Repeatability r;
  r.runs = bias.size();
  if (r.runs < 2) {
    r.error = "bias repeatability: needs at least 2 turn-ons, has " + std::to_string(r.runs);
    return r;
  }
  const double n = static_cast<double>(r.runs);
  for (const double b : bias)
    r.mean += b / n;
  double ss = 0.0;
  for (const double b : bias)
    ss += (b - r.mean) * (b - r.mean);
  r.std = std::sqrt(ss / (n - 1.0));
  r.sigma_mean = r.std / std::sqrt(n);
  // (N - 1) s^2 / sigma^2 ~ chi2(N - 1): the upper quantile bounds sigma from below.
  const double tail = 0.5 * (1.0 - confidence), dof = n - 1.0;
  r.std_lo = std::sqrt(ss / chi_square_quantile(1.0 - tail, dof));
  r.std_hi = std::sqrt(ss / chi_square_quantile(tail, dof));
  r.ok = true;
  return r;
}

TemperatureSlope bias_temperature_slope(std::span<const double> temperature_degc,
                                        std::span<const double> bias) {
  TemperatureSlope r;
  const std::size_t n = temperature_degc.size();
  if (bias.size() != n || n < 3) {
    r.error =
        "bias vs temperature: needs at least 3 (temperature, bias) pairs of equal count, has " +
        std::to_string(n) + " temperatures and " + std::to_string(bias.size()) + " biases";
    return r;
  }
  const double nd = static_cast<double>(n);
  double mt = 0.0, mb = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    mt += temperature_degc[i] / nd, mb += bias[i] / nd;
  double stt = 0.0, stb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    stt += (temperature_degc[i] - mt) * (temperature_degc[i] - mt);
    stb += (temperature_degc[i] - mt) * (bias[i] - mb);
  }
  if (!(stt > 0.0)) {
    r.error = "bias vs temperature: all records at one temperature";
    return r;
  }
  r.slope_per_degc = stb / stt;
  r.bias_at_mean = mb;
  r.mean_temperature_degc = mt;
  double ss = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = bias[i] - mb - r.slope_per_degc * (temperature_degc[i] - mt);
    ss += e * e;
  }
  r.residual_rms = std::sqrt(ss / nd);
  r.sigma_slope_per_degc = std::sqrt(ss / (nd - 2.0) / stt);
  r.ok = true;
  return r;
}

}  // namespace hrg::characterize
