// SPDX-License-Identifier: MIT
#pragma once

// The instantaneous coefficients of the resonator equations (physics.md
// section 1) for a temperature and an energy, shared by the full-rate and the
// averaged model so that both apply the effects identically.

#include <cmath>

#include "sim_target/params.hpp"

namespace hrg::sim::detail {

struct Coefficients {
  double omega_rad_s;  // mean angular frequency at this temperature
  double nu_per_s;     // mean damping, thermal and amplitude scaling included
  double dmu;
  double c4mu, s4mu;  // cos/sin 4 th_mu
  double dw2;         // (w_p^2 - w_q^2) / 2 = 2 w dw
  double c4w, s4w;    // cos/sin 4 th_w
  double kappa;       // Duffing cubic stiffness, 1/(s^2 V^2), 0 when off
  double spring_k;    // DC-pump stiffness per V^2 of V^2's DC part, 0 when off
};

inline double thermal_omega(const ResonatorParams& p, const Effects& fx, double temp_c) {
  double w = p.omega_rad_s();
  if (fx.thermal_frequency.enabled)
    w *= 1.0 + 1e-6 * fx.thermal_frequency.ppm_per_c * (temp_c - p.temp_ref_c);
  return w;
}

inline double damping_scale(const ResonatorParams& p, const Effects& fx, double temp_c,
                            double energy_v2) {
  double s = 1.0;
  if (fx.thermal_damping.enabled) s *= 1.0 + fx.thermal_damping.rel_per_c * (temp_c - p.temp_ref_c);
  if (fx.nonlinear_damping.enabled) s *= 1.0 + fx.nonlinear_damping.rel_per_v2 * energy_v2;
  return s;
}

inline Coefficients coefficients(const ResonatorParams& p, const Effects& fx, double temp_c,
                                 double energy_v2) {
  Coefficients c{};
  c.omega_rad_s = thermal_omega(p, fx, temp_c);
  c.nu_per_s = p.nu_per_s() * damping_scale(p, fx, temp_c, energy_v2);
  c.dmu = p.dmu;
  c.c4mu = std::cos(4.0 * p.th_mu_rad);
  c.s4mu = std::sin(4.0 * p.th_mu_rad);
  c.dw2 = 2.0 * c.omega_rad_s * p.half_split_rad_s();
  c.c4w = std::cos(4.0 * p.th_w_rad);
  c.s4w = std::sin(4.0 * p.th_w_rad);
  c.kappa =
      fx.duffing_stiffness.enabled ? fx.duffing_stiffness.kappa_per_s2_v2(p.omega_rad_s()) : 0.0;
  c.spring_k = fx.electrostatic_spring.enabled
                   ? -8.0 * kPi * p.omega_rad_s() * fx.electrostatic_spring.hz_per_v2
                   : 0.0;
  return c;
}

}  // namespace hrg::sim::detail
