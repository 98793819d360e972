// SPDX-License-Identifier: MIT
#include "firmware/calibration.hpp"

#include <bit>
#include <cmath>

namespace hrg::fw {

CalibrationBytes serialize(const Calibration& c) {
  CalibrationBytes b{};
  b[0] = kCalibrationFormatVersion;
  std::size_t at = 1;
  for (const CalibrationField& f : kCalibrationFields) {
    const uint64_t bits = std::bit_cast<uint64_t>(c.*f.member);
    for (int k = 0; k < 8; ++k)
      b[at++] = static_cast<uint8_t>(bits >> (8 * k));
  }
  return b;
}

bool deserialize(const CalibrationBytes& bytes, Calibration& out) {
  if (bytes[0] != kCalibrationFormatVersion) return false;
  Calibration c;
  std::size_t at = 1;
  for (const CalibrationField& f : kCalibrationFields) {
    uint64_t bits = 0;
    for (int k = 0; k < 8; ++k)
      bits |= static_cast<uint64_t>(bytes[at++]) << (8 * k);
    c.*f.member = std::bit_cast<double>(bits);
  }
  out = c;
  return true;
}

uint32_t crc32(const uint8_t* data, std::size_t n, uint32_t crc) {
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k)
      crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

uint32_t calibration_crc(const Calibration& c) {
  const CalibrationBytes b = serialize(c);
  return crc32(b.data(), b.size());
}

bool pickoff_correction(const Calibration& c, dsp::PickoffCorrection<double>& out) {
  return dsp::pickoff_correction_of(
      {c.pickoff_y_gain, c.pickoff_y_phase_rad, c.pickoff_y_misalignment_rad}, out);
}

bool pickoff_correction_q30(const Calibration& c, dsp::PickoffCorrectionQ30& out) {
  dsp::PickoffCorrection<double> k;
  return pickoff_correction(c, k) && dsp::to_q30(k, out);
}

dsp::FeedthroughCoefficients<double> feedthrough_coefficients(const Calibration& c) {
  return {c.feedthrough_x_re_v_per_v, c.feedthrough_x_im_v_per_v, c.feedthrough_y_re_v_per_v,
          c.feedthrough_y_im_v_per_v};
}

dsp::FeedthroughCoefficients<double> residual_at_raw_pickoffs(
    const Calibration& c, const dsp::FeedthroughCoefficients<double>& corrected) {
  const double c2b = std::cos(2.0 * c.pickoff_y_misalignment_rad);
  const double s2b = std::sin(2.0 * c.pickoff_y_misalignment_rad);
  const double a_re = c2b * corrected.y_re + s2b * corrected.x_re;
  const double a_im = c2b * corrected.y_im + s2b * corrected.x_im;
  // Times (1 + g) e^{-i phi}.
  const double cp = std::cos(c.pickoff_y_phase_rad);
  const double sp = std::sin(c.pickoff_y_phase_rad);
  const double gain = 1.0 + c.pickoff_y_gain;
  return {corrected.x_re, corrected.x_im, gain * (a_re * cp + a_im * sp),
          gain * (a_im * cp - a_re * sp)};
}

double frequency_offset_hz(const Calibration& c, double f_ref_hz, double temp_c, double a_A_v,
                           double pump_amplitude_v, bool pump_on) {
  double df = f_ref_hz * 1e-6 * c.thermal_frequency_ppm_per_c * (temp_c - c.temperature_ref_c);
  df += c.duffing_hz_per_v2 * a_A_v * a_A_v;
  if (pump_on) df += c.electrostatic_spring_hz_per_v2 * pump_amplitude_v * pump_amplitude_v;
  return df;
}

double damping_scale(const Calibration& c, double temp_c, double e_v2) {
  return (1.0 + c.thermal_damping_per_c * (temp_c - c.temperature_ref_c)) *
         (1.0 + c.nonlinear_damping_per_v2 * e_v2);
}

}  // namespace hrg::fw
