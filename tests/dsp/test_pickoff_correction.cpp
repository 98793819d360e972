// SPDX-License-Identifier: MIT
// Pickoff-map inverse and drive-feedthrough removal: the simulator's own
// measurement model (sim_target measure_envelopes) followed by the correction
// returns the true quadratures, to the bounds the kernels' contracts give.
#include "dsp/pickoff_correction.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <numbers>
#include <random>

#include "dsp/demodulator.hpp"
#include "dsp/nco.hpp"
#include "dsp/wave_variables.hpp"
#include "sim_target/averaged_model.hpp"
#include "support/cpputest.hpp"

using namespace hrg::dsp;
using cplx = std::complex<double>;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

hrg::sim::Effects pickoff_effects(const PickoffMap& m) {
  hrg::sim::Effects fx;
  fx.pickoff_gain_mismatch = {true, m.y_gain};
  fx.pickoff_phase_mismatch = {true, m.y_phase_rad / kDeg};
  fx.pickoff_misalignment = {true, m.y_misalignment_rad / kDeg};
  return fx;
}

struct Case {
  Quadratures<double> truth;
  Quadratures<double> measured;
};

// A standing wave through the simulator's measurement model.
Case measure(const hrg::sim::Effects& fx, double a_a, double a_b, double theta, double phase,
             cplx pump = {}) {
  cplx x;
  cplx y;
  hrg::sim::standing_wave(a_a, theta, a_b, phase, x, y);
  cplx xm;
  cplx ym;
  hrg::sim::measure_envelopes(fx, x, y, pump, xm, ym);
  return {quadratures_of_envelopes(x, y), quadratures_of_envelopes(xm, ym)};
}

double max_diff(const Quadratures<double>& a, const Quadratures<double>& b) {
  return std::max({std::fabs(a.cx - b.cx), std::fabs(a.sx - b.sx), std::fabs(a.cy - b.cy),
                   std::fabs(a.sy - b.sy)});
}

QuadSample<q31_t> to_q31(const Quadratures<double>& q) {
  return {q31_from_f64_sat(q.cx), q31_from_f64_sat(q.sx), q31_from_f64_sat(q.cy),
          q31_from_f64_sat(q.sy)};
}

Quadratures<double> of_q31(const QuadSample<q31_t>& q) {
  return {f64_from_q31(q.cx), f64_from_q31(q.sx), f64_from_q31(q.cy), f64_from_q31(q.sy)};
}

PickoffMap random_map(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> g(-0.05, 0.05);
  std::uniform_real_distribution<double> ang(-3.0, 3.0);
  return {g(rng), ang(rng) * kDeg, ang(rng) * kDeg};
}

}  // namespace

TEST_GROUP(PickoffCorrection){};

TEST(PickoffCorrection, SimulatorsMapThenInverseReturnsTheTruthInDoubleFloatAndQ31) {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double worst_d = 0.0;
  double worst_f = 0.0;
  double worst_q_lsb = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const PickoffMap map = random_map(rng);
    PickoffCorrection<double> k;
    CHECK_TRUE(pickoff_correction_of(map, k));
    const double a_a = 0.2 + 0.25 * (1.0 + unit(rng));
    const Case c = measure(pickoff_effects(map), a_a, 0.01 * unit(rng), unit(rng) * 3.0,
                           unit(rng) * std::numbers::pi);
    Quadratures<double> d = c.measured;
    correct_pickoffs(k, d);
    worst_d = std::max(worst_d, max_diff(d, c.truth));

    const PickoffCorrection<float> kf{static_cast<float>(k.kc), static_cast<float>(k.ks),
                                      static_cast<float>(k.m)};
    Quadratures<float> f{static_cast<float>(c.measured.cx), static_cast<float>(c.measured.sx),
                         static_cast<float>(c.measured.cy), static_cast<float>(c.measured.sy)};
    correct_pickoffs(kf, f);
    worst_f = std::max(worst_f, max_diff({f.cx, f.sx, f.cy, f.sy}, c.truth));

    // Q1.31: input quantisation (0.5 LSB through |kc|+|ks|+|m|), coefficient
    // quantisation (2^-31 each, times the input it multiplies: |q| LSB each
    // for |q| in full-scale units) and the final rounding (0.5 + 3 * 2^-28 LSB).
    PickoffCorrectionQ30 kq;
    CHECK_TRUE(to_q30(k, kq));
    QuadSample<q31_t> q = to_q31(c.measured);
    CHECK_FALSE(correct_pickoffs_q31(kq, q));
    const auto& m = c.measured;
    const double inputs = std::max(std::fabs(m.cy) + std::fabs(m.sy) + std::fabs(m.cx),
                                   std::fabs(m.cy) + std::fabs(m.sy) + std::fabs(m.sx));
    const double bound_lsb =
        0.5 * (std::fabs(k.kc) + std::fabs(k.ks) + std::fabs(k.m)) + inputs + 0.5 + 3.0 / (1 << 28);
    const double err_lsb = max_diff(of_q31(q), c.truth) * kQ31One;
    CHECK_TRUE(err_lsb <= bound_lsb);
    worst_q_lsb = std::max(worst_q_lsb, err_lsb);
  }
  CHECK_TRUE(worst_d < 1e-15);
  CHECK_TRUE(worst_f < 3e-7);     // a few float ulps of quadratures <= 0.7
  CHECK_TRUE(worst_q_lsb < 2.0);  // in practice well inside the bound (<= 3.1 LSB)
  std::printf("\n  pickoff round trip, max error: double %.2e, float %.2e, Q1.31 %.2f LSB\n",
              worst_d, worst_f, worst_q_lsb);
}

TEST(PickoffCorrection, GainMismatchFourThetaReadoutErrorIsRemoved) {
  // y_meas = (1 + g) y: tan 2theta_meas = (1 + g) tan 2theta, so the readout
  // error is ~ (g/4) sin 4theta rad, 0.1432 deg at g = 0.01; the level
  // E_meas / E = 1 + g(2 + g)(1 - cos 4theta)/2 peaks at 1 + 2g + g^2.
  const double g = 0.01;
  const PickoffMap map{g, 0.0, 0.0};
  hrg::sim::Effects fx;
  fx.pickoff_gain_mismatch = {true, g};
  PickoffCorrection<double> k;
  CHECK_TRUE(pickoff_correction_of(map, k));
  PickoffCorrectionQ30 kq;
  CHECK_TRUE(to_q30(k, kq));
  const double a = 0.5;
  double raw_deg = 0.0;
  double raw_level = 0.0;
  double fixed_deg = 0.0;
  double fixed_level = 0.0;
  for (int i = 0; i <= 720; ++i) {
    const double theta = (i / 720.0 - 0.5) * std::numbers::pi / 2.0 * 0.999;
    const Case c = measure(fx, a, 0.0, theta, 0.3);
    const auto raw = wave_variables(c.measured);
    raw_deg = std::max(raw_deg, std::fabs(raw.theta_A_rad - theta) / kDeg);
    raw_level = std::max(raw_level, raw.E_v2 / (a * a) - 1.0);
    QuadSample<q31_t> q = to_q31(c.measured);
    correct_pickoffs_q31(kq, q);
    const auto w = wave_variables(of_q31(q));
    fixed_deg = std::max(fixed_deg, std::fabs(w.theta_A_rad - theta) / kDeg);
    fixed_level = std::max(fixed_level, std::fabs(w.E_v2 / (a * a) - 1.0));
  }
  DOUBLES_EQUAL(g / 4.0 / kDeg, raw_deg, 0.003);  // 0.1432 deg
  DOUBLES_EQUAL(2.0 * g + g * g, raw_level, 1e-6);
  // Q1.31 after correction: ~LSB / a = 1e-9 rad.
  CHECK_TRUE(fixed_deg < 1e-6);
  CHECK_TRUE(fixed_level < 1e-8);
  std::printf("\n  4theta readout error, g = 0.01: raw %.4f deg, corrected (Q1.31) %.1e deg\n",
              raw_deg, fixed_deg);
}

TEST(PickoffCorrection, MapsWithoutAnInverseAreRefused) {
  PickoffCorrection<double> k{2.0, 3.0, 4.0};
  CHECK_FALSE(pickoff_correction_of({-1.0, 0.0, 0.0}, k));
  CHECK_FALSE(pickoff_correction_of({0.0, 0.0, 45.0 * kDeg}, k));
  CHECK_FALSE(pickoff_correction_of({NAN, 0.0, 0.0}, k));
  DOUBLES_EQUAL(2.0, k.kc, 0.0);  // unchanged
  PickoffCorrectionQ30 q;
  CHECK_FALSE(to_q30({2.0, 0.0, 0.0}, q));  // 2.0 is not a Q2.30 value
  CHECK_TRUE(to_q30({-2.0, 0.0, 0.0}, q));
  CHECK_EQUAL(INT32_MIN, q.kc_q30);
}

TEST(PickoffCorrection, Q31KernelHoldsItsContractAtTheRails) {
  // Identity is exact everywhere, both rails included.
  const PickoffCorrectionQ30 one{};
  for (q31_t v : {INT32_MIN, INT32_MIN + 1, -1, 0, 1, INT32_MAX}) {
    QuadSample<q31_t> q{v, v, v, v};
    CHECK_FALSE(correct_pickoffs_q31(one, q));
    CHECK_EQUAL(v, q.cy);
    CHECK_EQUAL(v, q.sy);
  }
  // Extreme coefficients (-2 each) on the negative rail: the sums (+6, +2)
  // saturate instead of wrapping and the kernel says so.
  const PickoffCorrectionQ30 worst{INT32_MIN, INT32_MIN, INT32_MIN};
  QuadSample<q31_t> q{INT32_MIN, INT32_MIN, INT32_MIN, INT32_MIN};
  CHECK_TRUE(correct_pickoffs_q31(worst, q));
  CHECK_EQUAL(INT32_MAX, q.cy);
  CHECK_EQUAL(INT32_MAX, q.sy);
  QuadSample<q31_t> p{INT32_MAX, INT32_MAX, INT32_MAX, INT32_MIN};
  CHECK_TRUE(correct_pickoffs_q31(worst, p));  // cy = -2(1 - 1 + 1) -> -2
  CHECK_EQUAL(INT32_MIN, p.cy);
  // Rounding: 0.5 x 1 LSB is a tie and goes up; 0.5 x -1 LSB goes up to 0.
  const PickoffCorrectionQ30 half{1 << 29, 0, 0};
  QuadSample<q31_t> t{0, 0, 1, -1};
  correct_pickoffs_q31(half, t);
  CHECK_EQUAL(1, t.cy);
  CHECK_EQUAL(0, t.sy);
}

TEST(PickoffCorrection, FeedthroughOfTheSimulatorIsRemovedInDoubleAndQ31) {
  hrg::sim::Effects fx;
  fx.drive_feedthrough = {true, 1e-3, -5e-4, 30.0, -120.0};
  const FeedthroughCoefficients<double> k{
      1e-3 * std::cos(30.0 * kDeg), 1e-3 * std::sin(30.0 * kDeg), -5e-4 * std::cos(-120.0 * kDeg),
      -5e-4 * std::sin(-120.0 * kDeg)};
  const double adc_fs = 2.0;
  const double dac_fs = 10.0;
  FeedthroughCoefficients<q31_t> kq;
  CHECK_TRUE(feedthrough_to_q31(k, adc_fs, dac_fs, kq));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double worst_d = 0.0;
  double worst_q_lsb = 0.0;
  for (int i = 0; i < 500; ++i) {
    const cplx pump = std::polar(8.0 * std::fabs(unit(rng)), 4.0 * unit(rng));  // volts
    const Case c = measure(fx, 1.0, 0.0, unit(rng), unit(rng), pump);
    CHECK_TRUE(max_diff(c.measured, c.truth) > 1e-4 * std::abs(pump));  // it is there
    Quadratures<double> d = c.measured;
    remove_feedthrough(k, pump.real(), pump.imag(), d);
    worst_d = std::max(worst_d, max_diff(d, c.truth));
    // Q1.31: quadratures in ADC full scale, pump in DAC full scale.
    Quadratures<double> m = c.measured;
    for (double* v : {&m.cx, &m.sx, &m.cy, &m.sy})
      *v /= adc_fs;
    QuadSample<q31_t> q = to_q31(m);
    CHECK_FALSE(remove_feedthrough_q31(kq, q31_from_f64_sat(pump.real() / dac_fs),
                                       q31_from_f64_sat(pump.imag() / dac_fs), q));
    Quadratures<double> back = of_q31(q);
    for (double* v : {&back.cx, &back.sx, &back.cy, &back.sy})
      *v *= adc_fs;
    const double err_lsb = max_diff(back, c.truth) / adc_fs * kQ31One;
    // 0.5 (input) + 0.5 LSB + 2^-30 (rounding) + the coefficients' rounding
    // (0.5 LSB each) times |Re P| + |Im P| in DAC full scale.
    const double bound =
        1.0 + 0.5 * (std::fabs(pump.real()) + std::fabs(pump.imag())) / dac_fs + 1e-9;
    CHECK_TRUE(err_lsb <= bound);
    worst_q_lsb = std::max(worst_q_lsb, err_lsb);
  }
  CHECK_TRUE(worst_d < 1e-15);
  CHECK_TRUE(worst_q_lsb < 1.5);
  std::printf("\n  feedthrough removal, max error: double %.2e V, Q1.31 %.2f LSB\n", worst_d,
              worst_q_lsb);
}

TEST(PickoffCorrection, FeedthroughQ31KernelSaturatesAtTheRails) {
  const FeedthroughCoefficients<q31_t> k{INT32_MIN, INT32_MIN, INT32_MIN, INT32_MIN};
  QuadSample<q31_t> q{INT32_MAX, INT32_MAX, INT32_MIN, INT32_MIN};
  // k P with k = P = -1 - i: Re = 0, Im = 2 (the Q2.62 products would sum to 2^63).
  CHECK_TRUE(remove_feedthrough_q31(k, INT32_MIN, INT32_MIN, q));
  CHECK_EQUAL(INT32_MAX, q.cx);  // - 0
  CHECK_EQUAL(INT32_MAX, q.sx);  // + 2 saturates
  CHECK_EQUAL(INT32_MIN, q.cy);
  CHECK_EQUAL(INT32_MAX, q.sy);  // -1 + 2
  FeedthroughCoefficients<q31_t> out{};
  CHECK_FALSE(feedthrough_to_q31({0.25, 0.0, 0.0, 0.0}, 2.0, 10.0, out));  // 1.25 FS per FS
  CHECK_FALSE(feedthrough_to_q31({0.0, 0.0, 0.0, 0.0}, 0.0, 10.0, out));
}

TEST(PickoffCorrection, PumpEnvelopeFilterFollowsTheDemodulatorAcrossSwitching) {
  // Feedthrough alone at the NCO frequency, the pump envelope constant per
  // block and switched on, turned in phase, and off. The demodulator's
  // baseband output is k times the filtered envelope exactly; what remains at
  // a switching block is the 2f mixing product, which the sinc^5 nulls only
  // for a steady envelope (its per-block weights are not flat). Subtracting
  // k P of the current block alone would leave most of each step.
  constexpr uint32_t kL = 100;
  const uint32_t step = phase_step_of_hz(5000.0, 100000.0);
  Demodulator<double> demod(kL);
  PumpEnvelopeFilter filter(kL);
  const auto w = filter.weights();
  double w_sum = 0.0;
  for (const double wk : w)
    w_sum += wk;
  DOUBLES_EQUAL(1.0, w_sum, 1e-14);
  // w0 = C(L + 4, 5) / L^5 for the sinc^5 decimator.
  DOUBLES_EQUAL(104.0 * 103.0 * 102.0 * 101.0 / 120e8, w[0], 1e-15);
  const cplx k = std::polar(0.4, 0.7);
  uint32_t phase = 0;
  double steady = 0.0;
  double switching = 0.0;
  double naive = 0.0;
  cplx prev[kDecimatorOrder - 1] = {};
  for (int n = 0; n < 16; ++n) {
    const cplx p = (n >= 3 && n < 9) ? std::polar(1.0, n >= 6 ? 2.0 : -0.5) : cplx{};
    q31_t frames[2 * kL];
    uint32_t ph = phase;
    for (uint32_t j = 0; j < kL; ++j) {
      const double wt = 2.0 * std::numbers::pi * (static_cast<double>(ph) / 4294967296.0);
      frames[2 * j] = q31_from_f64_sat(std::real(k * p * std::polar(1.0, wt)));
      frames[2 * j + 1] = 0;
      ph += step;
    }
    QuadSample<double> out;
    CHECK_TRUE(demod.process_block(frames, phase, step, out));
    double re = 0.0;
    double im = 0.0;
    filter.push(p.real(), p.imag(), re, im);
    const cplx got(out.cx, -out.sx);  // X = cx - i sx
    const double err = std::abs(got - k * cplx(re, im)) / std::abs(k);
    bool steady_block = true;
    for (const cplx& q : prev)
      steady_block = steady_block && q == p;
    (steady_block ? steady : switching) = std::max(steady_block ? steady : switching, err);
    if (!steady_block) naive = std::max(naive, std::abs(got - k * p) / std::abs(k));
    for (std::size_t i = kDecimatorOrder - 2; i > 0; --i)
      prev[i] = prev[i - 1];
    prev[0] = p;
  }
  std::printf(
      "\n  pump envelope filter: steady %.1e, switching %.1e (current block only: %.2f)"
      " of |k P|\n",
      steady, switching, naive);
  CHECK_TRUE(steady < 2e-5);     // the NCO table's 4.8e-6 FS and the input rounding
  CHECK_TRUE(switching < 0.02);  // the 2f product of a step
  CHECK_TRUE(naive > 0.5);
}
