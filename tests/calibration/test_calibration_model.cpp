// SPDX-License-Identifier: MIT
// The calibration's resonator model is the simulator's: thermal frequency and
// damping, nonlinear damping, Duffing and electrostatic spring evaluated by
// firmware/calibration.hpp against sim_target's own coefficients.
#include <cmath>
#include <complex>

#include "firmware/calibration.hpp"
#include "sim_target/averaged_model.hpp"
#include "../../sim_target/src/coefficients.hpp"

#include "support/cpputest.hpp"

using namespace hrg;

TEST_GROUP(CalibrationModel){};

TEST(CalibrationModel, DampingScaleAndThermalFrequencyAreTheSimulatorsCoefficients) {
  sim::ResonatorParams p;
  p.temp_ref_c = 31.5;
  sim::Effects fx;
  fx.thermal_frequency = {true, 5.0};
  fx.thermal_damping = {true, 0.004};
  fx.nonlinear_damping = {true, 0.05};
  fw::Calibration c;
  c.thermal_frequency_ppm_per_c = 5.0;
  c.thermal_damping_per_c = 0.004;
  c.nonlinear_damping_per_v2 = 0.05;
  c.temperature_ref_c = 31.5;
  for (double t : {29.5, 31.5, 33.0}) {
    for (double e : {0.0, 1.0, 2.25}) {
      DOUBLES_EQUAL(sim::detail::damping_scale(p, fx, t, e), fw::damping_scale(c, t, e), 1e-15);
    }
    const double f_sim = sim::detail::thermal_omega(p, fx, t) / (2.0 * M_PI);
    DOUBLES_EQUAL(f_sim - p.f_hz, fw::frequency_offset_hz(c, p.f_hz, t, 0.0, 0.0, false), 1e-9);
  }
}

TEST(CalibrationModel, DuffingAndSpringShiftTheAveragedModelsFrequencyAsCalibrated) {
  // The averaged model's detuning of a standing wave of amplitude a with a
  // pump of amplitude V0 on, against the calibrated offset c_d a^2 + c_s V0^2.
  sim::ResonatorParams p;
  sim::Effects fx;
  fx.duffing_stiffness = {true, 2e-3};
  fx.electrostatic_spring = {true, -1.11e-4};
  const auto k = sim::detail::coefficients(p, fx, p.temp_ref_c, 0.0);
  const double w = k.omega_rad_s;
  const double a = 1.5;
  const double v0 = 6.0;
  // Cubic stiffness kappa: a standing wave of amplitude a shifts by 3 kappa a^2 / (8 w);
  // the pump's DC stiffness spring_k <V^2> = spring_k V0^2 / 2 shifts by -spring_k V0^2 / (4 w).
  const double df_sim =
      (3.0 * k.kappa * a * a / (8.0 * w) - k.spring_k * v0 * v0 / (4.0 * w)) / (2.0 * M_PI);
  fw::Calibration c;
  c.duffing_hz_per_v2 = 2e-3;
  c.electrostatic_spring_hz_per_v2 = -1.11e-4;
  DOUBLES_EQUAL(df_sim, fw::frequency_offset_hz(c, p.f_hz, c.temperature_ref_c, a, v0, true),
                1e-12);
  DOUBLES_EQUAL(2e-3 * a * a, fw::frequency_offset_hz(c, p.f_hz, 25.0, a, v0, false), 1e-15);
}
