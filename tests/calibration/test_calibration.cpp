// SPDX-License-Identifier: MIT
// The firmware's Calibration: ranges, canonical form, CRC, the pickoff part in Q2.30.
#include "firmware/calibration.hpp"

#include <cmath>
#include <cstring>
#include <limits>

#include "firmware/calibration_constant.hpp"
#include "support/cpputest.hpp"

using namespace hrg::fw;

namespace {

Calibration measured_gyro() {
  Calibration c;
  c.pickoff_y_gain = 0.0101;
  c.pickoff_y_phase_rad = 1.0 * kDegToRad;
  c.pickoff_y_misalignment_rad = 0.5 * kDegToRad;
  c.feedthrough_x_re_v_per_v = 8.66e-4;
  c.feedthrough_x_im_v_per_v = 5e-4;
  c.thermal_frequency_ppm_per_c = 5.0;
  c.thermal_damping_per_c = 0.004;
  c.temperature_ref_c = 31.5;
  c.duffing_hz_per_v2 = 2e-3;
  c.electrostatic_spring_hz_per_v2 = -1.11e-4;
  c.nonlinear_damping_per_v2 = 0.05;
  c.gap_eps_p = 0.02;
  c.gap_eps_q = -0.01;
  return c;
}

}  // namespace

TEST_GROUP(Calibration){};

TEST(Calibration, IdentityAndBuiltInAreInRangeAndCorrectNothing) {
  CHECK_EQUAL(-1, first_out_of_range(kIdentityCalibration));
  CHECK_EQUAL(-1, first_out_of_range(built_in_calibration()));
  hrg::dsp::PickoffCorrectionQ30 q;
  CHECK_TRUE(pickoff_correction_q30(kIdentityCalibration, q));
  CHECK_EQUAL(1 << 30, q.kc_q30);
  CHECK_EQUAL(0, q.ks_q30);
  CHECK_EQUAL(0, q.m_q30);
}

TEST(Calibration, EachFieldOutOfRangeIsNamedByItsIndex) {
  for (std::size_t i = 0; i < kCalibrationFieldCount; ++i) {
    const CalibrationField& f = kCalibrationFields[i];
    for (double bad :
         {f.max + std::fabs(f.max) * 1e-9 + 1e-12, f.min - std::fabs(f.min) * 1e-9 - 1e-12,
          std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
      Calibration c = measured_gyro();
      c.*f.member = bad;
      CHECK_EQUAL(static_cast<int>(i), first_out_of_range(c));
    }
    Calibration edge;
    edge.*f.member = f.max;
    CHECK_EQUAL(-1, first_out_of_range(edge));
    edge.*f.member = f.min;
    CHECK_EQUAL(-1, first_out_of_range(edge));
  }
}

TEST(Calibration, CanonicalFormRoundTripsBitForBitAndItsCrcSeesEveryBit) {
  const Calibration c = measured_gyro();
  const CalibrationBytes b = serialize(c);
  CHECK_EQUAL(121u, b.size());
  CHECK_EQUAL(kCalibrationFormatVersion, b[0]);
  Calibration back;
  CHECK_TRUE(deserialize(b, back));
  CHECK_EQUAL(0, std::memcmp(serialize(back).data(), b.data(), b.size()));
  // Field order and byte order are fixed: gain is bytes 1..8, little-endian.
  double gain = 0.0;
  std::memcpy(&gain, b.data() + 1, 8);  // the host is little-endian like the M7
  DOUBLES_EQUAL(c.pickoff_y_gain, gain, 0.0);
  // The check value of CRC-32/ISO-HDLC.
  const uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  CHECK_EQUAL(0xCBF43926u, crc32(check, sizeof check));
  // A single flipped bit anywhere changes the CRC.
  const uint32_t crc = calibration_crc(c);
  for (std::size_t i = 0; i < b.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      CalibrationBytes f = b;
      f[i] ^= static_cast<uint8_t>(1u << bit);
      CHECK_TRUE(crc32(f.data(), f.size()) != crc);
    }
  }
  CalibrationBytes wrong = b;
  wrong[0] = 2;
  Calibration untouched = kIdentityCalibration;
  CHECK_FALSE(deserialize(wrong, untouched));
  DOUBLES_EQUAL(0.0, untouched.pickoff_y_gain, 0.0);
}

TEST(Calibration, PickoffPartInQ30MatchesTheDoubleInverseToHalfAnLsb) {
  const Calibration c = measured_gyro();
  hrg::dsp::PickoffCorrection<double> k;
  hrg::dsp::PickoffCorrectionQ30 q;
  CHECK_TRUE(pickoff_correction(c, k));
  CHECK_TRUE(pickoff_correction_q30(c, q));
  const double lsb = 1.0 / 1073741824.0;
  DOUBLES_EQUAL(k.kc, q.kc_q30 * lsb, 0.5 * lsb);
  DOUBLES_EQUAL(k.ks, q.ks_q30 * lsb, 0.5 * lsb);
  DOUBLES_EQUAL(k.m, q.m_q30 * lsb, 0.5 * lsb);
  // kc = cos(1 deg) / (1.0101 cos(1 deg)) = 1 / 1.0101, m = -tan(1 deg).
  DOUBLES_EQUAL(std::cos(kDegToRad) / (1.0101 * std::cos(kDegToRad)), k.kc, 1e-15);
  DOUBLES_EQUAL(-std::tan(kDegToRad), k.m, 1e-15);
  // Every calibration inside the ranges has a Q2.30 inverse (the extreme corner).
  Calibration corner;
  corner.pickoff_y_gain = kCalibrationFields[0].min;
  corner.pickoff_y_phase_rad = kCalibrationFields[1].max;
  corner.pickoff_y_misalignment_rad = kCalibrationFields[2].max;
  CHECK_TRUE(pickoff_correction_q30(corner, q));
}

TEST(Calibration, AResidualOnTheCorrectedQuadraturesIsReferredBackToTheRawPickoffs) {
  // GIVEN a feedthrough k at the raw pickoffs (X_ft = k_x P), P = 1 V at 0.3
  // rad, through the map's inverse as the chain applies it
  const Calibration c = measured_gyro();
  hrg::dsp::PickoffCorrection<double> inv;
  CHECK_TRUE(pickoff_correction(c, inv));
  const hrg::dsp::FeedthroughCoefficients<double> raw{3e-4, -2e-4, 7e-4, 4e-4};
  const double p_re = std::cos(0.3), p_im = std::sin(0.3);
  // X = k P appears as cx = Re(kP), sx = -Im(kP).
  hrg::dsp::Quadratures<double> q{
      raw.x_re * p_re - raw.x_im * p_im, -(raw.x_re * p_im + raw.x_im * p_re),
      raw.y_re * p_re - raw.y_im * p_im, -(raw.y_re * p_im + raw.y_im * p_re)};
  hrg::dsp::correct_pickoffs(inv, q);
  // The residual the switch-off check reads on them: r = X / P per channel.
  const auto per_volt = [&](double cx, double sx, double& re, double& im) {
    const double x_re = cx, x_im = -sx;
    re = x_re * p_re + x_im * p_im;
    im = x_im * p_re - x_re * p_im;
  };
  hrg::dsp::FeedthroughCoefficients<double> corrected;
  per_volt(q.cx, q.sx, corrected.x_re, corrected.x_im);
  per_volt(q.cy, q.sy, corrected.y_re, corrected.y_im);
  // (the y channel moved: 1 % gain, 1 deg phase, 1 deg of 2b of x in it)
  CHECK(std::fabs(corrected.y_re - raw.y_re) > 5e-6);
  // THEN referred back it is k again, to rounding
  const auto back = residual_at_raw_pickoffs(c, corrected);
  DOUBLES_EQUAL(raw.x_re, back.x_re, 1e-15);
  DOUBLES_EQUAL(raw.x_im, back.x_im, 1e-15);
  DOUBLES_EQUAL(raw.y_re, back.y_re, 1e-15);
  DOUBLES_EQUAL(raw.y_im, back.y_im, 1e-15);
  // AND with no pickoff map it is the residual itself
  const auto same = residual_at_raw_pickoffs(kIdentityCalibration, raw);
  DOUBLES_EQUAL(raw.y_im, same.y_im, 0.0);
}
