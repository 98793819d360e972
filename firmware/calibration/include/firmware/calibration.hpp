// SPDX-License-Identifier: MIT
#pragma once

// What the firmware can correct of a gyro's electronics and resonator, as
// measured (hrg audit --calibration, a CAN block, or a constant on bare
// metal). One fixed-size value type: no heap, no exceptions.
//
// The fields follow docs/effects-catalog.md (same definitions and signs),
// in SI units except where the name says otherwise. All zero (except the
// reference temperature, whose value does not matter then) is the identity:
// nothing is corrected.
//
// Every field has a physical range (kCalibrationFields); a calibration with a
// field outside it is refused as a whole. The canonical serialisation (for
// the CRC and the CAN block) is the format version byte followed by every
// field, in table order, as IEEE-754 binary64 little-endian.

#include <array>
#include <cstddef>
#include <cstdint>
#include <numbers>

#include "dsp/pickoff_correction.hpp"

namespace hrg::fw {

struct Calibration {
  // Pickoff map: Y_meas = (1 + g) e^{-i phi} (cos2b Y + sin2b X).
  double pickoff_y_gain = 0.0;              // g (-)
  double pickoff_y_phase_rad = 0.0;         // phi, y lags x (rad)
  double pickoff_y_misalignment_rad = 0.0;  // b, physical (rad)
  // Drive feedthrough k = c e^{i psi} per channel, per volt of pump, while it runs.
  double feedthrough_x_re_v_per_v = 0.0;
  double feedthrough_x_im_v_per_v = 0.0;
  double feedthrough_y_re_v_per_v = 0.0;
  double feedthrough_y_im_v_per_v = 0.0;
  // Resonator model: f(T) = f(T0)(1 + alpha (T - T0)); damping x (1 + beta (T - T0)).
  double thermal_frequency_ppm_per_c = 0.0;     // alpha (ppm/degC)
  double thermal_damping_per_c = 0.0;           // beta (1/degC)
  double temperature_ref_c = 25.0;              // T0 (degC)
  double duffing_hz_per_v2 = 0.0;               // frequency + c a^2 (Hz/V^2 of pickoff)
  double electrostatic_spring_hz_per_v2 = 0.0;  // frequency + c V_pump^2 while on (Hz/V^2)
  double nonlinear_damping_per_v2 = 0.0;  // damping x (1 + eta E), E in V^2 of pickoff (1/V^2)
  // Ring electrode gap: 1/d0^3 ~ 1 + eps_p cos4theta + eps_q sin4theta (instrument
  // axes, seed eqs. 25-29). Gives the pump's drift D_Phi (est::known_gap_drift_rad_s).
  double gap_eps_p = 0.0;  // eps_p (-)
  double gap_eps_q = 0.0;  // eps_q (-)
};

// One standard deviation of a calibration's gap harmonic (a file's
// gap_eps_p_sigma, gap_eps_q_sigma; zero: not given, the gap is taken as
// exact). Not part of the canonical form: a CAN block carries no sigma.
// Est::Estimator weighs it with its online pump fit's (check_known_gap).
struct GapSigma {
  double eps_p = 0.0;
  double eps_q = 0.0;
};

// One field: its key (unit in the name), its physical range, where it lives.
struct CalibrationField {
  const char* key;
  double min;
  double max;
  double Calibration::*member;
};

inline constexpr std::size_t kCalibrationFieldCount = 15;
inline constexpr double kDegToRad = std::numbers::pi / 180.0;

// Physical ranges: wide enough for any gyro the chain can run (a 20 % gain
// mismatch or a 10 deg misalignment is a broken pickoff, not a calibration),
// narrow enough that a corrupted or mis-scaled value (deg for rad, ppm for
// relative) is refused instead of applied.
inline constexpr std::array<CalibrationField, kCalibrationFieldCount> kCalibrationFields{{
    {"pickoff_y_gain", -0.2, 0.2, &Calibration::pickoff_y_gain},
    {"pickoff_y_phase_rad", -20.0 * kDegToRad, 20.0 * kDegToRad, &Calibration::pickoff_y_phase_rad},
    {"pickoff_y_misalignment_rad", -10.0 * kDegToRad, 10.0 * kDegToRad,
     &Calibration::pickoff_y_misalignment_rad},
    {"feedthrough_x_re_v_per_v", -0.1, 0.1, &Calibration::feedthrough_x_re_v_per_v},
    {"feedthrough_x_im_v_per_v", -0.1, 0.1, &Calibration::feedthrough_x_im_v_per_v},
    {"feedthrough_y_re_v_per_v", -0.1, 0.1, &Calibration::feedthrough_y_re_v_per_v},
    {"feedthrough_y_im_v_per_v", -0.1, 0.1, &Calibration::feedthrough_y_im_v_per_v},
    {"thermal_frequency_ppm_per_c", -500.0, 500.0, &Calibration::thermal_frequency_ppm_per_c},
    {"thermal_damping_per_c", -0.2, 0.2, &Calibration::thermal_damping_per_c},
    {"temperature_ref_c", -60.0, 150.0, &Calibration::temperature_ref_c},
    {"duffing_hz_per_v2", -1.0, 1.0, &Calibration::duffing_hz_per_v2},
    {"electrostatic_spring_hz_per_v2", -0.1, 0.1, &Calibration::electrostatic_spring_hz_per_v2},
    {"nonlinear_damping_per_v2", -1.0, 10.0, &Calibration::nonlinear_damping_per_v2},
    {"gap_eps_p", -0.2, 0.2, &Calibration::gap_eps_p},
    {"gap_eps_q", -0.2, 0.2, &Calibration::gap_eps_q},
}};

// Index of the first field outside its range (NaN included), or -1 when all are in range.
constexpr int first_out_of_range(const Calibration& c) {
  for (std::size_t i = 0; i < kCalibrationFields.size(); ++i) {
    const CalibrationField& f = kCalibrationFields[i];
    const double v = c.*f.member;
    if (!(v >= f.min && v <= f.max)) return static_cast<int>(i);
  }
  return -1;
}

// The identity: nothing corrected.
inline constexpr Calibration kIdentityCalibration{};
static_assert(first_out_of_range(kIdentityCalibration) < 0);

// Canonical serialisation: version byte + 15 x binary64 LE = 121 bytes.
inline constexpr uint8_t kCalibrationFormatVersion = 1;
inline constexpr std::size_t kCalibrationBytes = 1 + 8 * kCalibrationFieldCount;
using CalibrationBytes = std::array<uint8_t, kCalibrationBytes>;
CalibrationBytes serialize(const Calibration& c);
// false (out unchanged) on a wrong version byte; no range check (call
// first_out_of_range on the result).
bool deserialize(const CalibrationBytes& bytes, Calibration& out);

// CRC-32 (IEEE 802.3: reflected polynomial 0xEDB88320, init and final xor
// 0xFFFFFFFF; "123456789" gives 0xCBF43926).
uint32_t crc32(const uint8_t* data, std::size_t n, uint32_t crc = 0);
// CRC-32 of the canonical serialisation.
uint32_t calibration_crc(const Calibration& c);

// The pickoff part as the chain uses it: the inverse map's coefficients in
// double and Q2.30. false when the map has no inverse (outside the ranges
// it cannot happen).
bool pickoff_correction(const Calibration& c, dsp::PickoffCorrection<double>& out);
bool pickoff_correction_q30(const Calibration& c, dsp::PickoffCorrectionQ30& out);
// The feedthrough part, V/V.
dsp::FeedthroughCoefficients<double> feedthrough_coefficients(const Calibration& c);
// A residual feedthrough read on the corrected quadratures (fw::PumpEdgeCheck)
// referred to the raw pickoffs, where the calibration's feedthrough acts (it
// is removed before the pickoff map's inverse): X passes that inverse
// unchanged, Y_raw = (1 + g) e^{-i phi} (cos2b Y + sin2b X). Adding the
// result to feedthrough_coefficients(c) gives the feedthrough the edges saw.
dsp::FeedthroughCoefficients<double> residual_at_raw_pickoffs(
    const Calibration& c, const dsp::FeedthroughCoefficients<double>& corrected);

// The resonator part, as the catalogue defines it, at what the firmware
// measures (for feed-forward and the estimator's regressors):
// frequency offset from f_ref_hz (the frequency at T0, small amplitude, pump
// off), Hz: f_ref alpha (T - T0) + c_duffing a_A^2 + c_spring V_pump^2 (pump on;
// V_pump its amplitude).
double frequency_offset_hz(const Calibration& c, double f_ref_hz, double temp_c, double a_A_v,
                           double pump_amplitude_v, bool pump_on);
// Factor on the whole damping (mean and anisotropy): (1 + beta (T - T0))(1 + eta E),
// E = a_A^2 + a_B^2 (V^2 of pickoff).
double damping_scale(const Calibration& c, double temp_c, double e_v2);
// It has a damping part (damping_scale is not 1 everywhere).
constexpr bool has_damping_model(const Calibration& c) {
  return c.thermal_damping_per_c != 0.0 || c.nonlinear_damping_per_v2 != 0.0;
}

}  // namespace hrg::fw
