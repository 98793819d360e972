// SPDX-License-Identifier: MIT
#pragma once

#include <span>
#include <string>

namespace hrg::characterize {

// IEEE 1431 bias repeatability: the spread of the bias over N turn-ons.
struct Repeatability {
  std::size_t runs = 0;
  double mean = 0.0;
  double sigma_mean = 0.0;  // std / sqrt(N)
  double std = 0.0;         // sample standard deviation (N - 1): the repeatability
  double std_lo = 0.0;      // two-sided chi-square interval of std with N - 1 dof
  double std_hi = 0.0;
  bool ok = false;
  std::string error;
};
Repeatability bias_repeatability(std::span<const double> bias, double confidence = 0.683);

// Bias against temperature: least-squares slope (bias unit per degC) with its
// 1-sigma from the residuals, and the bias at the mean temperature.
struct TemperatureSlope {
  double slope_per_degc = 0.0;
  double sigma_slope_per_degc = 0.0;
  double bias_at_mean = 0.0;
  double mean_temperature_degc = 0.0;
  double residual_rms = 0.0;
  bool ok = false;
  std::string error;
};
TemperatureSlope bias_temperature_slope(std::span<const double> temperature_degc,
                                        std::span<const double> bias);

}  // namespace hrg::characterize
