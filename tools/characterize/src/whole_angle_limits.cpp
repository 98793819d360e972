// SPDX-License-Identifier: MIT
#include "characterize/whole_angle_limits.hpp"

#include <cmath>
#include <numbers>

namespace hrg::characterize {

double damping_rate_per_s(double frequency_hz, double q) {
  return std::numbers::pi * frequency_hz / q;
}

double rate_threshold_rad_s(double nu_per_s, double dmu, double k_angular_gain) {
  return nu_per_s * std::fabs(dmu) / std::fabs(k_angular_gain);
}

double mean_precession_rate_rad_s(double omega_rad_s, double nu_per_s, double dmu,
                                  double k_angular_gain) {
  const double input = k_angular_gain * omega_rad_s;
  const double drift = nu_per_s * std::fabs(dmu);
  if (std::fabs(input) <= drift) return 0.0;
  return -std::copysign(std::sqrt(input * input - drift * drift), input) / 2.0;
}

double free_decay_amplitude(double amplitude0, double t_s, double nu_per_s, double dmu,
                            double theta0_rad, double theta_mu_rad) {
  const double psi = 2.0 * (theta0_rad - theta_mu_rad);
  const double c = std::cos(psi), s = std::sin(psi);
  const double split = nu_per_s * dmu * t_s;
  return amplitude0 * std::exp(-nu_per_s * t_s) *
         std::sqrt(c * c * std::exp(-2.0 * split) + s * s * std::exp(2.0 * split));
}

double rundown_time_s(double amplitude0, double noise_floor, double nu_per_s, double dmu,
                      double theta0_rad, double theta_mu_rad) {
  if (amplitude0 <= noise_floor) return 0.0;
  // The amplitude falls monotonically (both axes decay, |dmu| < 1): bisect
  // between the times of the faster and the slower axis.
  const double ln_ratio = std::log(amplitude0 / noise_floor);
  double lo = ln_ratio / (nu_per_s * (1.0 + std::fabs(dmu)));
  double hi = ln_ratio / (nu_per_s * (1.0 - std::fabs(dmu)));
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double a = free_decay_amplitude(amplitude0, mid, nu_per_s, dmu, theta0_rad, theta_mu_rad);
    (a > noise_floor ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace hrg::characterize
