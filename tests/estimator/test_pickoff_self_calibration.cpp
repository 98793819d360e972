// SPDX-License-Identifier: MIT
// Online identification of the pickoff gain mismatch and misalignment from
// free-decay windows (closed-form decays of eq. 8 seen through the pickoff map).
#include <estimator/pickoff_self_calibration.hpp>

#include <cmath>
#include <cstdio>
#include <random>

#include "dsp/pickoff_correction.hpp"
#include "estimator/pickoff_evidence.hpp"
#include "synthetic_decay.hpp"

#include "support/cpputest.hpp"

using namespace hrg::est;
using hrg::est::test::DecayState;
using hrg::est::test::SyntheticDecay;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kK = 0.554;
constexpr double kMixedRates[] = {0.0, 100.0, -60.0, 30.0};

struct Map {
  double gain = 0.0;
  double misalignment_rad = 0.0;
  double phase_rad = 0.0;
};

// The measured sample: Y_meas = (1 + g) e^{-i phi}(cos2b Y + sin2b X), white noise on the
// four quadratures, the correction the firmware applies (if any), wave
// variables recomputed as the firmware does.
WaveSample measure(const DecayState& s, const Map& m, double noise_v, std::mt19937_64& rng,
                   const hrg::dsp::PickoffCorrection<double>& applied) {
  auto q = hrg::dsp::quadratures_of_wave<double>(s.a_A_v, s.a_B_v, s.theta_rad, 0.3);
  const double c2b = std::cos(2.0 * m.misalignment_rad);
  const double s2b = std::sin(2.0 * m.misalignment_rad);
  const double cy = (1.0 + m.gain) * (c2b * q.cy + s2b * q.cx);
  const double sy = (1.0 + m.gain) * (c2b * q.sy + s2b * q.sx);
  // Y e^{-i phi} with Y = cy - i sy.
  q.cy = std::cos(m.phase_rad) * cy - std::sin(m.phase_rad) * sy;
  q.sy = std::cos(m.phase_rad) * sy + std::sin(m.phase_rad) * cy;
  std::normal_distribution<double> n(0.0, noise_v);
  q.cx += n(rng);
  q.sx += n(rng);
  q.cy += n(rng);
  q.sy += n(rng);
  hrg::dsp::correct_pickoffs(applied, q);
  const auto w = hrg::dsp::wave_variables<double>(q);
  return WaveSample{s.t_s, w.a_A_v, w.a_B_v, w.theta_A_rad, w.E_v2};
}

// `count` free decays of `samples` ms at 1 kHz (white noise noise_v on each
// quadrature) from window `first` on, window w while the table turns at
// rates_dps[w % n], each starting at the set point at a new pattern angle;
// the mean damping of window w is nu (1 + nu_wobble sin(w)).
template <std::size_t N>
void feed_windows(PickoffSelfCalibration& cal, const Map& m, const double (&rates_dps)[N],
                  int first, int count, const hrg::dsp::PickoffCorrection<double>& applied = {},
                  double nu_wobble = 0.0, int samples = 1000, double noise_v = 1e-4) {
  std::mt19937_64 rng(16 + static_cast<unsigned>(first));
  for (int w = first; w < first + count; ++w) {
    ParamVector p = hrg::est::test::seed_params(20.0 * kDeg, 5.0 * kDeg);
    p(kNu) *= 1.0 + nu_wobble * std::sin(static_cast<double>(w));
    const SyntheticDecay decay(p, kK, rates_dps[static_cast<std::size_t>(w) % N] * kDeg);
    DecayState s{100.0 * w, 1.0, 1e-3, (13.0 * w) * kDeg};
    CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(cal.begin_window()));
    for (int i = 0; i < samples; ++i) {
      cal.add_sample(measure(s, m, noise_v, rng, applied));
      decay.step(s, 1e-3);
    }
    CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(cal.end_window()));
  }
}

template <std::size_t N>
PickoffSelfCalResult run_windows(const Map& m, const double (&rates_dps)[N], int windows,
                                 double max_kappa = kSelfCalMaxKappa,
                                 const hrg::dsp::PickoffCorrection<double>& applied = {},
                                 double nu_wobble = 0.0) {
  PickoffSelfCalibration cal;
  feed_windows(cal, m, rates_dps, 0, windows, applied, nu_wobble);
  return cal.solve(max_kappa);
}

}  // namespace

TEST_GROUP(PickoffSelfCalibration){};

TEST(PickoffSelfCalibration, GainAndMisalignmentComeFromTheLevelWhileTheTableTurns) {
  // Windows at rest and while the table turns (100 deg/s turns the pattern
  // 28 deg per 1 s window, K = 0.554): at rest the anisotropy shows alone in
  // the decay rate, turning adds the pickoff's level pattern.
  const Map truth{0.01, 0.5 * kDeg};
  const PickoffSelfCalResult r = run_windows(truth, kMixedRates, 40);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r.status));
  CHECK_EQUAL(30, r.turning_windows);
  std::printf(
      "\n  self-calibration, 40 windows at 0/100/-60/30 deg/s: g %.5f +- %.1e (truth 0.01), "
      "b %.4f +- %.4f deg (truth 0.5), kappa %.1f\n",
      r.gain, r.gain_sigma, r.misalignment_rad / kDeg, r.misalignment_sigma_rad / kDeg, r.kappa_2);
  // The model is exact in rho and bh, with the O(g^2) 8theta terms free:
  // what is left is O(g^3) ~ 1e-6.
  DOUBLES_EQUAL(truth.gain, r.gain, 3.0 * r.gain_sigma + 1e-6);
  DOUBLES_EQUAL(truth.misalignment_rad, r.misalignment_rad, 3.0 * r.misalignment_sigma_rad + 1e-6);
  CHECK_TRUE(r.decay_consistent);
  CHECK_TRUE(r.gain_sigma < 1e-4);
  // The damping terms solved alongside are the resonator's (seed: nu = pi f / Q,
  // dmu 0.05 at 20 deg): the gain mismatch is not taken for anisotropy.
  const ParamVector p = hrg::est::test::seed_params(20.0 * kDeg, 5.0 * kDeg);
  DOUBLES_EQUAL(p(kNu), r.nu_per_s, 0.02 * p(kNu));
  DOUBLES_EQUAL(p(kDnuC), r.dnu_c_per_s, 0.1 * p(kNu) * 0.05);
  DOUBLES_EQUAL(p(kDnuS), r.dnu_s_per_s, 0.1 * p(kNu) * 0.05);
}

TEST(PickoffSelfCalibration, StrongMapsReadTrueOverLongWindowsWithTheCubicOfTheLevelModelled) {
  // GIVEN 40 windows of 5 s (the long-run plan's length) at rest and turning,
  // 1e-5 V of noise, through the pickoff map itself (ln E_meas = ln E -
  // ln(1 + u) exactly): u of amplitude A = 0.035 (b 1 deg), 0.070 (2 deg),
  // 0.049 (g -5 %). A level model cut after u^2/2 reads the 4theta pattern
  // scaled by 1 + A^2/4 (b 1 deg: 1.0003 deg, ~80 of its sigmas here) and
  // leaves the 12theta part A^3/12 in the windows, where it reads as a decay
  // slope of its own per window (decay F ~30 against 1.9).
  const Map maps[] = {{0.0, 1.0 * kDeg}, {0.0, 2.0 * kDeg}, {-0.05, 0.0}};
  for (const Map& truth : maps) {
    PickoffSelfCalibration cal;
    feed_windows(cal, truth, kMixedRates, 0, 40, {}, 0.0, 5000, 1e-5);
    const PickoffSelfCalResult r = cal.solve();
    CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r.status));
    const LevelHarmonics h = level_harmonics_of(truth.gain, truth.misalignment_rad);
    std::printf(
        "\n  5 s windows, g %.2f b %.1f deg: g %.7f +- %.1e, b %.6f +- %.1e deg, phi %.1e +- "
        "%.1e deg, decay F %.2f (limit %.2f), 12theta (%.2e, %.2e) for (%.2e, %.2e)\n",
        truth.gain, truth.misalignment_rad / kDeg, r.gain, r.gain_sigma, r.misalignment_rad / kDeg,
        r.misalignment_sigma_rad / kDeg, r.phase_rad / kDeg, r.phase_sigma_rad / kDeg, r.decay_f,
        r.decay_f_limit, r.level_12th_c, r.level_12th_s, h.k_c, h.k_s);
    // THEN the map reads within 1.5 of its sigmas (what is left out, the
    // 16theta harmonic beta^4 / 2, is 1.5e-7 of ln E at most here),
    DOUBLES_EQUAL(truth.gain, r.gain, 1.5 * r.gain_sigma);
    DOUBLES_EQUAL(truth.misalignment_rad, r.misalignment_rad, 1.5 * r.misalignment_sigma_rad);
    // AND one decay rate holds, as it does in these windows,
    CHECK_TRUE(r.decay_consistent);
    // AND the quadrature row reads no phase lag the gyro does not have: the
    // split acting at the true angle and the level u on the quadrature read
    // -0.0041 deg at b 1 deg without their terms; what is left is second
    // order in the map (-3.0e-5 deg at b 1 deg, -1.1e-4 at 2 deg).
    CHECK_TRUE(std::fabs(r.phase_rad) < 2e-4 * kDeg);
    // AND the 12theta terms are the map's own, -(2/3) w^3 (3.6e-6 at 1 deg,
    // 2.9e-5 at 2 deg), to a tenth of the larger.
    const double k = std::hypot(h.k_c, h.k_s);
    DOUBLES_EQUAL(h.k_c, r.level_12th_c, 0.1 * k);
    DOUBLES_EQUAL(h.k_s, r.level_12th_s, 0.1 * k);
  }
}

TEST(PickoffSelfCalibration, AStrongMapPutInForceIsReadThroughItsCorrectionOverLongWindows) {
  // GIVEN g 3 % and b -1.5 deg, 20 windows of 5 s: identified, the
  // evidence-weighted map put in force and the windows re-referred through
  // the step (its level harmonics, its damping cross terms, the anisotropy
  // columns turned by 2b)
  const Map truth{0.03, -1.5 * kDeg};
  PickoffSelfCalibration cal;
  feed_windows(cal, truth, kMixedRates, 0, 20, {}, 0.0, 5000, 1e-5);
  const PickoffSelfCalResult r1 = cal.solve();
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r1.status));
  const PickoffMap target = evidence_weighted_map({}, r1);
  cal.refer_to_applied(step_between({}, target, r1));
  // WHEN 20 more windows come through the correction
  hrg::dsp::PickoffCorrection<double> k1;
  CHECK_TRUE(hrg::dsp::pickoff_correction_of(
      {target.gain, target.phase_rad, target.misalignment_rad}, k1));
  feed_windows(cal, truth, kMixedRates, 20, 20, k1, 0.0, 5000, 1e-5);
  const PickoffSelfCalResult r2 = cal.solve();
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r2.status));
  const PickoffMapEstimate e = whole_estimate(target, r2);
  std::printf(
      "\n  g 0.03 b -1.5 deg, 5 s windows, 20 + 20 through the step: g %.7f +- %.1e, b %.6f +- "
      "%.1e deg, decay F %.2f (limit %.2f); dnu (%.4e, %.4e) +- %.1e\n",
      e.value.gain, e.sigma.gain, e.value.misalignment_rad / kDeg, e.sigma.misalignment_rad / kDeg,
      r2.decay_f, r2.decay_f_limit, r2.dnu_c_per_s, r2.dnu_s_per_s, r2.dnu_s_sigma_per_s);
  // THEN the whole estimate is the truth within 2 of its sigmas and one
  // decay rate holds over all 40 windows,
  DOUBLES_EQUAL(truth.gain, e.value.gain, 2.0 * e.sigma.gain);
  DOUBLES_EQUAL(truth.misalignment_rad, e.value.misalignment_rad, 2.0 * e.sigma.misalignment_rad);
  CHECK_TRUE(r2.decay_consistent);
  // AND the anisotropy is the resonator's, in the frame of the correction
  // (seed: dmu 0.05 at 20 deg, nu pi 5e3 / 5e6)
  const ParamVector p = hrg::est::test::seed_params(20.0 * kDeg, 5.0 * kDeg);
  DOUBLES_EQUAL(p(kDnuC), r2.dnu_c_per_s, 4.0 * r2.dnu_c_sigma_per_s);
  DOUBLES_EQUAL(p(kDnuS), r2.dnu_s_per_s, 4.0 * r2.dnu_s_sigma_per_s);
}

TEST(PickoffSelfCalibration, TheLevelHarmonicsAreThoseOfMinusLnOnePlusU) {
  // GIVEN a strong map (g 5 %, b 2 deg): u = rho r - 2 bh s, A = 0.086
  const double g = 0.05;
  const double b = 2.0 * kDeg;
  const LevelHarmonics h = level_harmonics_of(g, b);
  const double k = (1.0 + g) * (1.0 + g);
  const double rho = (k - 1.0) / (k + 1.0);
  const double bh = 0.5 * std::sin(2.0 * b) * std::sqrt(1.0 - rho * rho);
  // WHEN -ln(1 + u) is sampled over one turn of x = 4theta (r = cos x, s = sin x)
  // and its harmonics taken by quadrature
  constexpr int kN = 720;
  double c1 = 0.0, s1 = 0.0, c2 = 0.0, s2 = 0.0, c3 = 0.0, s3 = 0.0;
  for (int i = 0; i < kN; ++i) {
    const double x = 2.0 * M_PI * i / kN;
    const double y = -std::log(1.0 + rho * std::cos(x) - 2.0 * bh * std::sin(x)) * 2.0 / kN;
    c1 += y * std::cos(x);
    s1 += y * std::sin(x);
    c2 += y * std::cos(2.0 * x);
    s2 += y * std::sin(2.0 * x);
    c3 += y * std::cos(3.0 * x);
    s3 += y * std::sin(3.0 * x);
  }
  // THEN the columns' coefficients are those harmonics (the columns: -r, 2s;
  // (r^2 - s^2)/2 = cos2x / 2, rs = sin2x / 2; cos3x, sin3x) to rounding,
  DOUBLES_EQUAL(-c1, h.rho_f, 1e-14);
  DOUBLES_EQUAL(s1 / 2.0, h.bh_f, 1e-14);
  DOUBLES_EQUAL(2.0 * c2, h.h_c, 1e-14);
  DOUBLES_EQUAL(2.0 * s2, h.h_s, 1e-14);
  DOUBLES_EQUAL(c3, h.k_c, 1e-14);
  DOUBLES_EQUAL(s3, h.k_s, 1e-14);
  // AND the 4theta pair is the map's scaled by 1 + A^2/4 to O(A^4)
  const double a2 = rho * rho + 4.0 * bh * bh;
  // (2 beta / A = 1 + A^2/4 + A^4/8 + ...)
  DOUBLES_EQUAL(rho * (1.0 + a2 / 4.0), h.rho_f, 0.2 * a2 * a2 * rho);
  DOUBLES_EQUAL(bh * (1.0 + a2 / 4.0), h.bh_f, 0.2 * a2 * a2 * bh);
}

TEST(PickoffSelfCalibration, AModelThatTookTheLevelPatternForDampingStandsOutOfItsSigmas) {
  // GIVEN the pickoff map identified with the damping alongside
  const Map truth{0.01, 0.5 * kDeg};
  const PickoffSelfCalResult r = run_windows(truth, kMixedRates, 40);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r.status));
  CHECK_TRUE(r.dnu_c_sigma_per_s > 0.0 && r.dnu_s_sigma_per_s > 0.0);
  const double sc = r.dnu_c_sigma_per_s;
  const double ss = r.dnu_s_sigma_per_s;
  // THEN the true damping stands within its sigmas (sqrt 2 of each: both
  // fits' sigmas count), a model whose dnu_S is 20 sigmas off stands at
  // 20 / sqrt 2 = 14.1 less what the estimate's own error moves it by,
  ParamVector p = hrg::est::test::seed_params(20.0 * kDeg, 5.0 * kDeg);
  const double z_true = hrg::est::damping_anisotropy_disagreement_sigmas(r, p, sc, ss);
  CHECK_TRUE(z_true < 3.0);
  p(kDnuS) += 20.0 * ss;
  const double z_off = hrg::est::damping_anisotropy_disagreement_sigmas(r, p, sc, ss);
  DOUBLES_EQUAL(20.0 / std::sqrt(2.0), z_off, z_true + 1e-9);
  // and when the windows did not hold one decay rate, the fit with a decay
  // rate per window speaks instead (here its dnu_S 20 of the model's sigma
  // and its own from the model's),
  PickoffSelfCalResult inconsistent = r;
  inconsistent.decay_consistent = false;
  inconsistent.per_window_dnu_c_per_s = p(kDnuC);
  inconsistent.per_window_dnu_s_per_s = p(kDnuS) - 20.0 * ss;
  inconsistent.per_window_dnu_c_sigma_per_s = ss;
  inconsistent.per_window_dnu_s_sigma_per_s = ss;
  DOUBLES_EQUAL(20.0 / std::sqrt(2.0),
                hrg::est::damping_anisotropy_disagreement_sigmas(inconsistent, p, sc, ss), 1e-9);
  // and nothing is said when the solve was refused.
  PickoffSelfCalResult refused = r;
  refused.status = Status::ill_conditioned;
  DOUBLES_EQUAL(0.0, hrg::est::damping_anisotropy_disagreement_sigmas(refused, p, sc, ss), 0.0);
}

TEST(PickoffSelfCalibration, TheReadoutPatternsSignificanceIsTheLargerOfGainAndMisalignment) {
  // GIVEN the 1 % gain and 0.5 deg misalignment identified from mixed rates
  const PickoffSelfCalResult r = run_windows(Map{0.01, 0.5 * kDeg}, kMixedRates, 40);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r.status));
  // THEN the pattern stands the larger of |g| / sigma_g and |b| / sigma_b out
  // (g sigma ~5e-6: thousands of sigmas, far above the firmware's 5)
  const double z = hrg::est::readout_pattern_sigmas(r);
  DOUBLES_EQUAL(std::max(r.gain / r.gain_sigma, r.misalignment_rad / r.misalignment_sigma_rad), z,
                1e-9 * z);
  CHECK_TRUE(z > 100.0);
  // AND ideal pickoffs stand within the noise
  const PickoffSelfCalResult ideal = run_windows(Map{}, kMixedRates, 40);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(ideal.status));
  CHECK_TRUE(hrg::est::readout_pattern_sigmas(ideal) < 4.0);
  // AND where one decay rate does not hold, the fit with a rate per window speaks
  PickoffSelfCalResult inconsistent = r;
  inconsistent.decay_consistent = false;
  const double z_w = std::max(r.per_window_gain / r.per_window_gain_sigma,
                              r.per_window_misalignment_rad / r.per_window_misalignment_sigma_rad);
  DOUBLES_EQUAL(z_w, hrg::est::readout_pattern_sigmas(inconsistent), 1e-9 * z_w);
  // AND nothing is said when the solve was refused
  PickoffSelfCalResult refused = r;
  refused.status = Status::ill_conditioned;
  DOUBLES_EQUAL(0.0, hrg::est::readout_pattern_sigmas(refused), 0.0);
}

TEST(PickoffSelfCalibration, AppliedAndIdentifiedAgainTheResidualMapVanishes) {
  // The firmware applies the identified inverse and keeps identifying on the
  // corrected signals: what is left is within the noise.
  const Map truth{0.01, 0.5 * kDeg};
  const PickoffSelfCalResult r1 = run_windows(truth, kMixedRates, 40);
  hrg::dsp::PickoffCorrection<double> k1;
  CHECK_TRUE(hrg::dsp::pickoff_correction_of({r1.gain, 0.0, r1.misalignment_rad}, k1));
  const PickoffSelfCalResult r2 = run_windows(truth, kMixedRates, 40, kSelfCalMaxKappa, k1);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r2.status));
  // Total map identified: (1 + g1)(1 + g2) - 1 and b1 + b2 (to first order).
  const double g = (1.0 + r1.gain) * (1.0 + r2.gain) - 1.0;
  const double b = r1.misalignment_rad + r2.misalignment_rad;
  std::printf(
      "\n  second pass on corrected signals: residual g %.1e +- %.1e, b %.1e deg; total g "
      "%.6f, b %.5f deg\n",
      r2.gain, r2.gain_sigma, r2.misalignment_rad / kDeg, g, b / kDeg);
  CHECK_TRUE(std::fabs(g - truth.gain) < 3.0 * r2.gain_sigma + 5e-6);
  CHECK_TRUE(std::fabs(b - truth.misalignment_rad) < 3.0 * r2.misalignment_sigma_rad + 5e-6);
}

TEST(PickoffSelfCalibration, AnIdealPickoffGivesZeroWithinItsSigma) {
  const PickoffSelfCalResult r = run_windows(Map{}, kMixedRates, 40);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r.status));
  CHECK_TRUE(std::fabs(r.gain) < 4.0 * r.gain_sigma);
  CHECK_TRUE(std::fabs(r.misalignment_rad) < 4.0 * r.misalignment_sigma_rad);
  CHECK_TRUE(std::fabs(r.phase_rad) < 4.0 * r.phase_sigma_rad);
  CHECK_TRUE(r.decay_consistent);
}

TEST(PickoffSelfCalibration, ThePhaseLagComesFromTheQuadratureLevelWhileTheTableTurns) {
  // phi puts a^2 phi sin4th into Q; within a turning window it follows the
  // pattern angle, while the split grows the true quadrature (its integral).
  const Map truth{0.0, 0.0, 1.0 * kDeg};
  const PickoffSelfCalResult r = run_windows(truth, kMixedRates, 40);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r.status));
  std::printf(
      "\n  phase 1 deg: phi %.5f +- %.5f deg, split dw_C %.4e dw_S %.4e rad/s, kappa %.1f\n",
      r.phase_rad / kDeg, r.phase_sigma_rad / kDeg, r.dw_c_rad_s, r.dw_s_rad_s, r.kappa_2_quad);
  DOUBLES_EQUAL(truth.phase_rad, r.phase_rad, 3.0 * r.phase_sigma_rad + 1e-6);
  CHECK_TRUE(r.phase_sigma_rad < 0.01 * kDeg);
  // The split solved alongside is the resonator's (seed: dw = pi 5e-4 rad/s at 5 deg).
  const ParamVector p = hrg::est::test::seed_params(20.0 * kDeg, 5.0 * kDeg);
  DOUBLES_EQUAL(p(kDwC), r.dw_c_rad_s, 0.01 * p(kDwC));
  DOUBLES_EQUAL(p(kDwS), r.dw_s_rad_s, 0.01 * p(kDwC));
  // E does not see the phase.
  CHECK_TRUE(std::fabs(r.gain) < 4.0 * r.gain_sigma);
  CHECK_TRUE(std::fabs(r.misalignment_rad) < 4.0 * r.misalignment_sigma_rad);
}

TEST(PickoffSelfCalibration, WindowsReReferredThroughTheAppliedCorrectionAllCount) {
  // 20 windows identify the map, the firmware applies it, 20 more come
  // through the correction: the re-referred state's residual comes from all
  // 40 (its sigma that of 40), and the total is the truth.
  const Map truth{0.01, 0.5 * kDeg, 0.5 * kDeg};
  PickoffSelfCalibration cal;
  feed_windows(cal, truth, kMixedRates, 0, 20);
  const PickoffSelfCalResult r1 = cal.solve();
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r1.status));
  cal.refer_to_applied(r1);
  const PickoffSelfCalResult r0 = cal.solve();
  // Right after: nothing left.
  CHECK_TRUE(std::fabs(r0.gain) < 1e-9 && std::fabs(r0.misalignment_rad) < 1e-9 &&
             std::fabs(r0.phase_rad) < 1e-9);
  hrg::dsp::PickoffCorrection<double> k1;
  CHECK_TRUE(hrg::dsp::pickoff_correction_of({r1.gain, r1.phase_rad, r1.misalignment_rad}, k1));
  feed_windows(cal, truth, kMixedRates, 20, 20, k1);
  const PickoffSelfCalResult r2 = cal.solve();
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r2.status));
  const double g = (1.0 + r1.gain) * (1.0 + r2.gain) - 1.0;
  const double b = r1.misalignment_rad + r2.misalignment_rad;
  const double phi = r1.phase_rad + r2.phase_rad;
  std::printf(
      "\n  20 windows, applied, 20 more: g sigma %.1e -> %.1e; total g %.6f, b %.5f deg, phi "
      "%.5f deg\n",
      r1.gain_sigma, r2.gain_sigma, g, b / kDeg, phi / kDeg);
  CHECK_TRUE(r2.gain_sigma < 0.8 * r1.gain_sigma);
  CHECK_TRUE(std::fabs(g - truth.gain) < 3.0 * r2.gain_sigma + 2e-6);
  CHECK_TRUE(std::fabs(b - truth.misalignment_rad) < 3.0 * r2.misalignment_sigma_rad + 2e-6);
  // The quadrature row holds the map's first-order terms: what is left is
  // second order, 2.7e-4 deg here (1.1e-3 before those terms were held).
  CHECK_TRUE(std::fabs(phi - truth.phase_rad) < 3.0 * r2.phase_sigma_rad + 0.002 * kDeg);
}

TEST(PickoffSelfCalibration, APartTheGyroDoesNotHaveIsWeighedByItsEvidence) {
  // GIVEN a gain mismatch alone, 20 windows
  const Map truth{0.01, 0.0, 0.0};
  PickoffSelfCalibration cal;
  feed_windows(cal, truth, kMixedRates, 0, 20);
  const PickoffSelfCalResult r1 = cal.solve();
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r1.status));
  // WHEN the firmware weighs the estimate part by part
  const PickoffMap target = evidence_weighted_map({}, r1);
  std::printf(
      "\n  gain alone, 20 windows: estimate b %.1e +- %.1e deg, phi %.1e +- %.1e deg; "
      "put in force b %.1e, phi %.1e deg\n",
      r1.misalignment_rad / kDeg, r1.misalignment_sigma_rad / kDeg, r1.phase_rad / kDeg,
      r1.phase_sigma_rad / kDeg, target.misalignment_rad / kDeg, target.phase_rad / kDeg);
  // THEN the gain (~2000 sigma) goes in whole, and the misalignment and the
  // phase the gyro does not have stand nearer their truth than the estimate.
  DOUBLES_EQUAL(r1.gain, target.gain, 1e-3 * r1.gain_sigma);
  CHECK_TRUE(std::fabs(target.misalignment_rad) <= std::fabs(r1.misalignment_rad));
  CHECK_TRUE(std::fabs(target.phase_rad) <= std::fabs(r1.phase_rad));
  // AND through the step, the windows read the whole estimate less what is
  // in force: the misalignment and phase left out are still there (the
  // misalignment read through sqrt(1 - rho^2) of the gain left, 5e-5 of it).
  cal.refer_to_applied(step_between({}, target, r1));
  const PickoffSelfCalResult r0 = cal.solve();
  DOUBLES_EQUAL(r1.misalignment_rad - target.misalignment_rad, r0.misalignment_rad,
                1e-3 * r1.misalignment_sigma_rad);
  DOUBLES_EQUAL(r1.phase_rad - target.phase_rad, r0.phase_rad, 1e-12);
  DOUBLES_EQUAL((1.0 + r1.gain) / (1.0 + target.gain) - 1.0, r0.gain, 1e-3 * r1.gain_sigma);
  // AND 20 more windows through the correction: the whole estimate is the
  // truth, and what goes in force after them no farther from it.
  hrg::dsp::PickoffCorrection<double> k1;
  CHECK_TRUE(hrg::dsp::pickoff_correction_of(
      {target.gain, target.phase_rad, target.misalignment_rad}, k1));
  feed_windows(cal, truth, kMixedRates, 20, 20, k1);
  const PickoffSelfCalResult r2 = cal.solve();
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r2.status));
  const PickoffMapEstimate e = whole_estimate(target, r2);
  CHECK_TRUE(std::fabs(e.value.gain - truth.gain) < 3.0 * e.sigma.gain + 2e-6);
  CHECK_TRUE(std::fabs(e.value.misalignment_rad) < 3.0 * e.sigma.misalignment_rad);
  const PickoffMap next = evidence_weighted_map(target, r2);
  CHECK_TRUE(std::fabs(next.misalignment_rad) <= std::fabs(e.value.misalignment_rad));
  CHECK_TRUE(std::fabs(next.phase_rad) <= std::fabs(e.value.phase_rad));
}

TEST(PickoffSelfCalibration, ADampingThatChangesBetweenWindowsFailsTheDecayTest) {
  // An ideal pickoff, the mean damping 2 % different from window to window
  // (temperature, amplitude): each window's slope departs from the common nu
  // by 2 dnu ~ 1.3e-4 1/s, ~6 of its sigma. The per-window decay test sees it.
  const PickoffSelfCalResult r = run_windows(Map{}, kMixedRates, 40, kSelfCalMaxKappa, {}, 0.02);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r.status));
  std::printf("\n  nu +-2 %% between windows: decay F %.1f (limit %.2f), g %.1e +- %.1e\n",
              r.decay_f, r.decay_f_limit, r.gain, r.gain_sigma);
  CHECK_FALSE(r.decay_consistent);
  CHECK_TRUE(r.decay_f > 2.0 * r.decay_f_limit);
}

TEST(PickoffSelfCalibration, WhereTheDecayTestRefusesTheWindowsOwnRatesStillReadTheGain) {
  // GIVEN the damping 2 % different from window to window, which the decay
  // test refuses the common-nu fit for
  const PickoffSelfCalResult ideal =
      run_windows(Map{}, kMixedRates, 40, kSelfCalMaxKappa, {}, 0.02);
  const PickoffSelfCalResult gain =
      run_windows(Map{0.02, 0.0}, kMixedRates, 40, kSelfCalMaxKappa, {}, 0.02);
  CHECK_FALSE(ideal.decay_consistent);
  CHECK_FALSE(gain.decay_consistent);
  std::printf(
      "\n  nu +-2 %% between windows, rate per window: g %.5f +- %.1e (truth 0.02), "
      "ideal %.1e +- %.1e\n",
      gain.per_window_gain, gain.per_window_gain_sigma, ideal.per_window_gain,
      ideal.per_window_gain_sigma);
  // THEN the fit with a decay rate per window reads a -0.02 ... 0.02 gain
  // within its sigmas, thousands of them from zero: the readout check
  // speaks (it said 0 here before),
  CHECK_TRUE(std::fabs(gain.per_window_gain - 0.02) < 4.0 * gain.per_window_gain_sigma);
  CHECK_TRUE(hrg::est::readout_pattern_sigmas(gain) > 100.0);
  // AND the damping that changes between windows reads as no pattern there
  CHECK_TRUE(hrg::est::readout_pattern_sigmas(ideal) < 4.0);
}

TEST(PickoffSelfCalibration, APhaseLagsDriftShareIsTwoNuPhiOverTheAnisotropy) {
  // GIVEN a 1 deg phase lag identified from mixed rates
  const PickoffSelfCalResult r = run_windows(Map{0.0, 0.0, 1.0 * kDeg}, kMixedRates, 40);
  CHECK_EQUAL(static_cast<int>(Status::ok), static_cast<int>(r.status));
  // THEN it stands |phi| / sigma_phi from zero, thousands of sigmas
  const double z = hrg::est::readout_phase_sigmas(r);
  DOUBLES_EQUAL(std::fabs(r.phase_rad) / r.phase_sigma_rad, z, 1e-9 * z);
  CHECK_TRUE(z > 100.0);
  // AND its drift 2 nu |phi| against the model's |dnu| (seed_params: nu
  // dmu = 0.05 nu): 2 phi / 0.05 = 0.70 at 1 deg, above the 1/2 beyond
  // which the compensated output may be worse than raw
  const ParamVector p = hrg::est::test::seed_params(20.0 * kDeg, 5.0 * kDeg);
  const double share = hrg::est::readout_phase_drift_share(r, p);
  DOUBLES_EQUAL(2.0 * p(kNu) * std::fabs(r.phase_rad) / std::hypot(p(kDnuC), p(kDnuS)), share,
                1e-12);
  DOUBLES_EQUAL(40.0 * std::fabs(r.phase_rad), share, 1e-9);
  CHECK_TRUE(share > 0.6);
  // AND ideal pickoffs stand within the noise; a refused solve says nothing
  const PickoffSelfCalResult ideal = run_windows(Map{}, kMixedRates, 40);
  CHECK_TRUE(hrg::est::readout_phase_sigmas(ideal) < 4.0);
  PickoffSelfCalResult refused = r;
  refused.status = Status::ill_conditioned;
  DOUBLES_EQUAL(0.0, hrg::est::readout_phase_sigmas(refused), 0.0);
  DOUBLES_EQUAL(0.0, hrg::est::readout_phase_drift_share(refused, p), 0.0);
}

TEST(PickoffSelfCalibration, WithoutWindowsAtDifferentRatesTheSolveIsRefused) {
  // At rest the level pattern does not change within a window: g and b are
  // not seen at all.
  const double rest[] = {0.0};
  PickoffSelfCalResult r = run_windows(Map{0.01, 0.0}, rest, 40);
  CHECK_EQUAL(static_cast<int>(Status::ill_conditioned), static_cast<int>(r.status));
  CHECK_EQUAL(0, r.turning_windows);
  // At one constant rate w, g cos4th changes at -4 g w sin4th: exactly the
  // rate pattern of a damping anisotropy (the integral of a 4theta pattern at
  // constant w is a 4theta pattern). The condition check sees the collinearity.
  const double constant[] = {100.0};
  r = run_windows(Map{0.01, 0.0}, constant, 40);
  CHECK_EQUAL(static_cast<int>(Status::ill_conditioned), static_cast<int>(r.status));
  std::printf("\n  one constant rate: kappa %.3g (refused above %.0e)\n", r.kappa_2,
              kSelfCalMaxKappa);
}

TEST(PickoffSelfCalibration, SequencingAndBadSamplesAreRefused) {
  PickoffSelfCalibration cal;
  CHECK_EQUAL(static_cast<int>(Status::not_in_window),
              static_cast<int>(cal.add_sample({0.0, 1.0, 0.0, 0.0, 1.0})));
  CHECK_EQUAL(static_cast<int>(Status::not_in_window), static_cast<int>(cal.end_window()));
  cal.begin_window();
  CHECK_EQUAL(static_cast<int>(Status::in_window), static_cast<int>(cal.begin_window()));
  CHECK_EQUAL(static_cast<int>(Status::bad_sample),
              static_cast<int>(cal.add_sample({0.0, 1.0, 0.0, 0.0, 0.0})));
  cal.add_sample({1.0, 1.0, 0.0, 0.0, 1.0});
  CHECK_EQUAL(static_cast<int>(Status::time_not_increasing),
              static_cast<int>(cal.add_sample({1.0, 1.0, 0.0, 0.0, 1.0})));
  CHECK_EQUAL(static_cast<int>(Status::too_short), static_cast<int>(cal.end_window()));
  CHECK_EQUAL(static_cast<int>(Status::no_data), static_cast<int>(cal.solve().status));
}
