// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>

#include "sim_target/params.hpp"

namespace hrg::sim::test {

// Free-decay rates of physics.md section 2 that both resonator models are held
// to: the amplitude decay rate of a standing wave at pattern angle theta_rad
// (1/s) and the growth rate of its quadrature per volt of a_A (1/s).
inline double amplitude_decay_per_s(const ResonatorParams& p, double theta_rad) {
  return p.nu_per_s() * (1.0 + p.dmu * std::cos(4.0 * (theta_rad - p.th_mu_rad)));
}

inline double quadrature_growth_per_s(const ResonatorParams& p, double theta_rad) {
  return p.half_split_rad_s() * std::sin(4.0 * (theta_rad - p.th_w_rad));
}

}  // namespace hrg::sim::test
