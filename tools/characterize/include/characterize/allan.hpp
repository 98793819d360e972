// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

namespace hrg::characterize {

// Power-law exponent alpha of the rate's spectral density S(f) ~ f^alpha
// (rate = "frequency", angle = "phase" in the time-and-frequency literature).
namespace power_law {
constexpr int kWhiteAngle = 2;       // angle quantization / white readout noise
constexpr int kFlickerAngle = 1;     // flicker angle noise
constexpr int kWhiteRate = 0;        // angle random walk
constexpr int kFlickerRate = -1;     // bias instability
constexpr int kRandomWalkRate = -2;  // rate random walk
}  // namespace power_law

// Equivalent degrees of freedom of the overlapping Allan variance at
// tau = m tau0 from n_angle angle samples, for power-law noise alpha in
// [-2, 2]: the exact sum of Greenhall and Riley (2003) for a second
// difference (d = 2), filter factor F = m and stride S = m.
double edf_overlapping_adev(int alpha, std::size_t m, std::size_t n_angle);

struct AllanPoint {
  double tau_s = 0.0;
  std::size_t m = 0;      // averaging factor: tau = m tau0
  double adev = 0.0;      // same unit as the rate (rad/s if the angle is in rad)
  std::size_t terms = 0;  // second differences averaged: n_angle - 2 m
  int alpha = 0;          // noise type the edf was computed for
  double edf = 0.0;
  double adev_lo = 0.0;  // two-sided chi-square interval, adev_lo <= adev <= adev_hi
  double adev_hi = 0.0;
};

struct AllanOptions {
  double confidence = 0.683;  // two-sided level of [adev_lo, adev_hi]
  // Noise type for the edf at every tau; empty: from the curve's local slope
  // (sigma^2 ~ tau^mu gives alpha = -mu - 1, kept to the types above).
  std::optional<int> alpha;
  // Averaging factors m (tau = m tau0); empty: octaves 1, 2, 4, ... plus the
  // m nearest tau = 1 s and 3 s (where ARW and rate random walk are read).
  std::vector<std::size_t> m;
};

// The angle series (integral of the rate) sampled every tau0_s:
// sigma^2(m tau0) = sum_i (x[i+2m] - 2 x[i+m] + x[i])^2 / (2 (m tau0)^2 (N - 2m)),
// for every m with N - 2m >= 2.
std::vector<AllanPoint> allan_from_angle(std::span<const double> angle, double tau0_s,
                                         const AllanOptions& options = {});

// A rate series (each sample the mean rate over its tau0_s): integrated to
// N + 1 angle samples first, so the same noise gives the same figures as its
// angle series (rate data are not phase data).
std::vector<AllanPoint> allan_from_rate(std::span<const double> rate, double tau0_s,
                                        const AllanOptions& options = {});

}  // namespace hrg::characterize
