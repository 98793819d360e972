// SPDX-License-Identifier: MIT
#pragma once

namespace hrg::characterize {

// Closed forms of the whole-angle mode in the convention of
// shared/docs/physics.md: precession theta' = -(K Omega - D(theta)) / 2 with
// the damping drift D_nu = nu dmu sin 4(theta - th_mu), nu = w / 2Q the mean
// amplitude decay rate and dmu the damping anisotropy (Delta(1/tau) = 2 nu dmu).

// Mean amplitude decay rate nu = pi f / Q (1/s); the energy E decays at 2 nu.
double damping_rate_per_s(double frequency_hz, double q);

// Rate threshold (dead zone): below |Omega| = nu |dmu| / K a pattern angle
// exists where the input term equals the drift and the pattern stops there
// (it is caught by the damping axis). Compensation leaves the residual
// anisotropy: pass dmu - dmu_identified.
double rate_threshold_rad_s(double nu_per_s, double dmu, double k_angular_gain);

// Mean precession rate of the pattern with that drift (Adler's equation):
// 0 inside the dead zone, -sign(Omega) sqrt((K Omega)^2 - (nu dmu)^2) / 2 outside,
// so the apparent scale factor near the threshold is sqrt(1 - (Omega_th / Omega)^2).
double mean_precession_rate_rad_s(double omega_rad_s, double nu_per_s, double dmu,
                                  double k_angular_gain);

// Free decay (excitation off) from amplitude a0 at pattern angle theta0: the
// wave splits onto the damping axes, th_mu decaying at nu (1 + dmu) and
// th_mu + 45 deg at nu (1 - dmu), so with psi = 2 (theta0 - th_mu)
//   a(t)^2 = a0^2 e^(-2 nu t) (cos^2 psi e^(-2 nu dmu t) + sin^2 psi e^(2 nu dmu t))
// and the pattern drifts to the less damped axis on the way.
double free_decay_amplitude(double amplitude0, double t_s, double nu_per_s, double dmu,
                            double theta0_rad, double theta_mu_rad);

// Run-down time: until that amplitude reaches the noise floor (the angle is
// lost); 0 if a0 <= a_floor. On an axis it is ln(a0 / a_floor) / (nu (1 +- dmu)).
double rundown_time_s(double amplitude0, double noise_floor, double nu_per_s, double dmu,
                      double theta0_rad, double theta_mu_rad);

}  // namespace hrg::characterize
