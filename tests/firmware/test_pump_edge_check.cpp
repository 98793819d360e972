// SPDX-License-Identifier: MIT
// PumpEdgeCheck: the corrected quadratures of a wave whose state is
// continuous at the switch-off, plus a residual feedthrough r P while the
// pump runs. The check reads r back from the step of the two sides' lines at
// the switch instant, with the noise the line-extrapolation formula gives,
// and says `step` when r V0 is above the readout tolerance 2 a sin(theta_tol).
#include "firmware/pump_edge_check.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <random>
#include <vector>

#include "dsp/demodulator.hpp"

#include "support/cpputest.hpp"
#include "support/decimator_taps.hpp"

using hrg::fw::ChainRecord;
using hrg::fw::PumpEdgeCheck;
using hrg::fw::PumpEdgeCheckConfig;
using hrg::fw::PumpEdgeStatus;
using hrg::fw::PumpEdgeVerdict;
using cplx = std::complex<double>;

namespace {

constexpr double kNoiseV = 3e-5;  // per quadrature and row (the default chain's, ~CRB)
constexpr double kPumpV = 3.0;
constexpr double kPumpPhaseRad = 0.7;
constexpr double kAmplitudeV = 1.0;

// The noise of the demodulator's rows: white Gaussian samples (the
// standardised mt19937_64, Box-Muller by hand: the same bits on every
// standard library) through its fifth-order decimator, one block of L
// samples per row, so successive rows share samples as the chain's do;
// scaled to kNoiseV per row.
class Noise {
 public:
  static constexpr int kBlock = 100;  // the default chain's block
  static constexpr int kTaps = static_cast<int>(hrg::dsp::kDecimatorOrder) * (kBlock - 1) + 1;

  Noise() {
    kernel_ = hrg::test::decimator_taps(kBlock);
    double sum_sq = 0.0;
    for (double h : kernel_)
      sum_sq += h * h;
    for (double& h : kernel_)
      h /= std::sqrt(sum_sq);  // unit sd per row
    for (auto& s : samples_)
      s.assign(kTaps, 0.0);
    for (int i = 0; i <= kTaps / kBlock; ++i)
      row();  // a full window before the first row
  }
  // The next row's noise on the 4 quadratures (V).
  std::array<double, 4> row() {
    std::array<double, 4> out{};
    for (std::size_t c = 0; c < 4; ++c) {
      auto& s = samples_[c];
      std::rotate(s.begin(), s.begin() + kBlock, s.end());
      for (int i = kTaps - kBlock; i < kTaps; ++i)
        s[i] = white();
      for (int i = 0; i < kTaps; ++i)
        out[c] += kernel_[i] * s[i];
      out[c] *= kNoiseV;
    }
    return out;
  }

 private:
  double white() {
    const double u1 = (static_cast<double>(rng_() >> 11) + 0.5) * 0x1.0p-53;
    const double u2 = static_cast<double>(rng_() >> 11) * 0x1.0p-53;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.141592653589793 * u2);
  }
  std::mt19937_64 rng_{2026};
  std::vector<double> kernel_;
  std::array<std::vector<double>, 4> samples_;
};

// One switch-off edge: `on_rows` rows with the pump on, then `off_rows`
// without. The true envelopes are lines in the row index with a kink at the
// switch instant t_e (the pump stops adding energy, the quadrature loop
// stops holding a_B): continuous there. Pump-on rows carry r P; the rows
// inside the demodulator's averaging span after the switch carry nonsense.
struct EdgeFeed {
  PumpEdgeCheckConfig cfg{};
  cplx r_x{0.0, 0.0};
  cplx r_y{0.0, 0.0};
  Noise noise{};
  // The NCO: advance per row, and how far it turns away from that after the
  // switch-off (the PLL answering a phase step), approached as 1 - e^{-t/20}.
  uint32_t nco_advance = 0x9e3779b9u;
  double nco_turn_rad = 0.0;
  uint32_t nco_base = 0;
  // The pump's amplitude swinging row to row by this fraction (the AGC's chatter).
  double pump_swing = 0.0;
  // The pump's level against kPumpV (the AGC's pump beating between its limits).
  double pump_scale = 1.0;
  // The pump held at 0 before this row (relative to the last pump-on row;
  // the AGC's pump leaving its lower limit), and the vibration growing by this
  // fraction per V^2 and row while it runs (the parametric pump's energy).
  double pump_rise_row = -1e9;
  double growth_per_v2_row = 0.0;
  // Row time: advances by row_s per row over every run.
  double t_s = 0.0;
  double row_s = 0.01;

  void run(PumpEdgeCheck& c, uint32_t on_rows, uint32_t off_rows) {
    const double t_e = cfg.edge_offset_rows;
    const cplx x_e{kAmplitudeV * 0.8, -0.05};
    const cplx y_e{kAmplitudeV * 0.6, 0.02};
    for (uint32_t k = 0; k < on_rows + off_rows; ++k) {
      const bool on = k < on_rows;
      // Row index relative to the last pump-on row (0).
      const double t = static_cast<double>(k) - static_cast<double>(on_rows - 1);
      const cplx slope_x = on ? cplx{0.0, 1e-6} : cplx{-2.5e-6, 3e-6};
      const cplx slope_y = on ? cplx{1e-6, 0.0} : cplx{-2e-6, -4e-6};
      cplx x = x_e + slope_x * (t - t_e);
      cplx y = y_e + slope_y * (t - t_e);
      const double level = pump_scale * kPumpV;
      const double v0 = t < pump_rise_row
                            ? 0.0
                            : level * (1.0 + pump_swing * std::sin(0.7 * static_cast<double>(k)));
      if (on && growth_per_v2_row != 0.0) {
        // The integral of V^2 from t_e back to t (the level held from the rise on).
        const double since_rise = std::max(0.0, t - pump_rise_row);
        const double bend =
            growth_per_v2_row * level * level * (since_rise - (t_e - pump_rise_row));
        x += x_e * bend;
        y += y_e * bend;
      }
      const cplx p = std::polar(v0, kPumpPhaseRad);
      if (on) {
        x += r_x * p;
        y += r_y * p;
      } else if (t < cfg.drive_free_rows) {
        x += cplx{0.01, 0.01};  // the switching transient in the averaging span
      }
      // The NCO's phase at the row's centre runs ahead of the steady
      // advance by turn(t); its block end is row_centre_blocks later.
      const auto turn = [&](double tc) {
        return tc > 0.0 ? nco_turn_rad * (1.0 - std::exp(-tc / 20.0)) : 0.0;
      };
      const double t_end = t + cfg.row_centre_blocks;
      const double end_rad = turn(t_end);
      x *= std::polar(1.0, -turn(t));
      y *= std::polar(1.0, -turn(t));
      ChainRecord row{};
      row.nco_phase = nco_base + static_cast<uint32_t>(k) * nco_advance +
                      static_cast<uint32_t>(static_cast<int32_t>(
                          std::lround(end_rad / 6.283185307179586 * 4294967296.0)));
      const std::array<double, 4> n = noise.row();
      row.quad_v = {x.real() + n[0], -x.imag() + n[1], y.real() + n[2], -y.imag() + n[3]};
      row.pump_v = on ? v0 : 0.0;
      row.pump_seen_v = on ? v0 : 0.0;
      row.pump_phase_rad = kPumpPhaseRad;
      row.wave.a_A_v = kAmplitudeV;
      row.t_s = t_s;
      t_s += row_s;
      c.add_row(row, on);
    }
  }
};

// Noise of one part of r from one edge: both lines' extrapolation to t_e,
// var = sigma^2 (1/N + (t_e - mean t)^2 / Sxx), Sxx = N (N^2 - 1) / 12, for
// independent rows; the decimator's rows vary kappa = 2.3233 times more
// (dsp::decimator_row_noise_correlation).
double sigma_r_one_edge(const PumpEdgeCheckConfig& cfg) {
  const double n = cfg.fit_rows;
  const double sxx = n * (n * n - 1.0) / 12.0;
  const double pre_mean = -(n - 1.0) / 2.0;
  const double post_mean = cfg.drive_free_rows + (n - 1.0) / 2.0;
  const double d_pre = cfg.edge_offset_rows - pre_mean;
  const double d_post = cfg.edge_offset_rows - post_mean;
  const double f = 2.0 / n + (d_pre * d_pre + d_post * d_post) / sxx;
  return kNoiseV * std::sqrt(f * hrg::dsp::decimator_row_noise_correlation(Noise::kBlock)) / kPumpV;
}

double tolerance_v(const PumpEdgeCheckConfig& cfg) {
  return 2.0 * kAmplitudeV * std::sin(cfg.max_readout_step_rad);
}

}  // namespace

TEST_GROUP(PumpEdgeCheck){};

TEST(PumpEdgeCheck, AContinuousStateShowsNoStepWithTheNoiseTheLinesPredict) {
  // GIVEN a wave with no residual feedthrough, one switch-off
  EdgeFeed feed;
  PumpEdgeCheck c(feed.cfg);
  feed.run(c, 200, 100);
  // THEN one edge, r within 4 sigma of 0, the sigma of the line formula
  // (estimated from the fits' residuals: within 10 %)
  LONGS_EQUAL(1, c.status().edges);
  const double sigma = sigma_r_one_edge(feed.cfg);
  DOUBLES_EQUAL(sigma, c.status().sigma_v_per_v, 0.1 * sigma);
  DOUBLES_EQUAL(0.0, c.status().x_re, 4.0 * sigma);
  DOUBLES_EQUAL(0.0, c.status().x_im, 4.0 * sigma);
  DOUBLES_EQUAL(0.0, c.status().y_re, 4.0 * sigma);
  DOUBLES_EQUAL(0.0, c.status().y_im, 4.0 * sigma);
  // AND the step is far below the tolerance of 0.005 deg of readout
  // (2 * 1 V * sin(8.73e-5) = 1.745e-4 V): consistent
  DOUBLES_EQUAL(1.745e-4, c.status().tolerance_v, 1e-7);
  CHECK(c.status().verdict == PumpEdgeVerdict::consistent);
}

TEST(PumpEdgeCheck, AResidualFeedthroughIsReadBackAndAStepAboveTheToleranceFails) {
  // GIVEN residual feedthrough r_x = 2e-4 at 0.3 rad, r_y = -1e-4 V/V:
  // a step of 6e-4 V at 3 V of pump, 3.4x the tolerance
  EdgeFeed feed;
  feed.r_x = std::polar(2e-4, 0.3);
  feed.r_y = {-1e-4, 0.0};
  PumpEdgeCheck c(feed.cfg);
  feed.run(c, 200, 100);
  // THEN r is read back within 4 sigma per part
  const double sigma = sigma_r_one_edge(feed.cfg);
  DOUBLES_EQUAL(feed.r_x.real(), c.status().x_re, 4.0 * sigma);
  DOUBLES_EQUAL(feed.r_x.imag(), c.status().x_im, 4.0 * sigma);
  DOUBLES_EQUAL(feed.r_y.real(), c.status().y_re, 4.0 * sigma);
  DOUBLES_EQUAL(feed.r_y.imag(), c.status().y_im, 4.0 * sigma);
  DOUBLES_EQUAL(2e-4 * kPumpV, c.status().step_v, 4.0 * sigma * kPumpV);
  CHECK(c.status().verdict == PumpEdgeVerdict::step);
}

TEST(PumpEdgeCheck, AStepAtTheToleranceIsUndecidedAndHalfOfItConsistent) {
  EdgeFeed feed;
  const PumpEdgeCheckConfig& cfg = feed.cfg;
  // GIVEN a step equal to the tolerance (within the 3 sigma band either side)
  feed.r_x = {tolerance_v(cfg) / kPumpV, 0.0};
  PumpEdgeCheck c(cfg);
  feed.run(c, 200, 100);
  CHECK(c.status().verdict == PumpEdgeVerdict::unknown);
  // GIVEN half the tolerance (7.7 sigma below it)
  PumpEdgeCheck half(cfg);
  feed.r_x = {0.5 * tolerance_v(cfg) / kPumpV, 0.0};
  feed.run(half, 200, 100);
  CHECK(half.status().verdict == PumpEdgeVerdict::consistent);
}

TEST(PumpEdgeCheck, EdgesAverageAndAResetForgetsThem) {
  EdgeFeed feed;
  PumpEdgeCheck c(feed.cfg);
  // GIVEN four edges: the sigma of the mean is half that of one
  for (int i = 0; i < 4; ++i)
    feed.run(c, 200, 100);
  LONGS_EQUAL(4, c.status().edges);
  const double sigma = sigma_r_one_edge(feed.cfg);
  DOUBLES_EQUAL(0.5 * sigma, c.status().sigma_v_per_v, 0.05 * sigma);
  // WHEN the correction changes (reset) and the next edge has a large residual
  c.reset();
  CHECK(c.status().verdict == PumpEdgeVerdict::unknown);
  LONGS_EQUAL(0, c.status().edges);
  feed.r_x = {1e-3, 0.0};
  feed.run(c, 200, 100);
  // THEN only that edge counts
  LONGS_EQUAL(1, c.status().edges);
  DOUBLES_EQUAL(1e-3, c.status().x_re, 4.0 * sigma);
  CHECK(c.status().verdict == PumpEdgeVerdict::step);
}

TEST(PumpEdgeCheck, AnEdgeAtANearZeroPumpDoesNotScaleAFeedthroughReadAtTheOthersDown) {
  // GIVEN r_x = 2e-4 V/V (a step of 6e-4 V at 3 V of pump, 3.4x the
  // tolerance), three edges at 3 V and then one at 0.01 V (the AGC's pump
  // near its lower limit): that edge reads r 300x noisier
  EdgeFeed feed;
  feed.r_x = {2e-4, 0.0};
  PumpEdgeCheck c(feed.cfg);
  for (int i = 0; i < 3; ++i)
    feed.run(c, 200, 100);
  feed.pump_scale = 0.01 / kPumpV;
  feed.run(c, 200, 100);
  LONGS_EQUAL(4, c.status().edges);
  // THEN the mean keeps the 3 V edges' r (each weighted by its noise: the
  // last one's weight is 1e-5 of theirs) and their sigma, 1/sqrt(3) of one
  const double sigma = sigma_r_one_edge(feed.cfg);
  DOUBLES_EQUAL(sigma / std::sqrt(3.0), c.status().sigma_v_per_v, 0.05 * sigma);
  DOUBLES_EQUAL(2e-4, c.status().x_re, 4.0 * sigma);
  // AND the step is judged at the largest pump seen, 3 V, not at the last
  // edge's 0.01 V (where it would be 2e-6 V, "consistent"): a step
  DOUBLES_EQUAL(2e-4 * kPumpV, c.status().step_v, 4.0 * sigma * kPumpV);
  CHECK(c.status().verdict == PumpEdgeVerdict::step);
}

TEST(PumpEdgeCheck, TooFewRowsOnEitherSideAreNoEdge) {
  EdgeFeed feed;
  feed.r_x = {1e-3, 0.0};
  PumpEdgeCheck c(feed.cfg);
  // GIVEN fewer pump-on rows than the fit needs, then an off stretch shorter
  // than the transient plus the fit
  feed.run(c, 40, 100);
  feed.run(c, 200, 60);
  // THEN nothing is measured
  LONGS_EQUAL(0, c.status().edges);
  CHECK(c.status().verdict == PumpEdgeVerdict::unknown);
}

TEST(PumpEdgeCheck, PumpOnRowsOutsideOperationStartThePumpOnSideAgain) {
  EdgeFeed feed;
  feed.r_x = {1e-3, 0.0};
  PumpEdgeCheck c(feed.cfg);
  ChainRecord ring_up{};
  ring_up.pump_v = 10.0;
  // GIVEN 200 steady rows, then a row of ring-up (the loops do not hold the
  // wave), then fewer steady rows than the fit needs before the switch-off
  feed.run(c, 200, 0);
  c.add_row(ring_up, true, false);
  feed.run(c, 40, 100);
  // THEN no edge is measured
  LONGS_EQUAL(0, c.status().edges);
}

TEST(PumpEdgeCheck, TheNcoTurningAfterTheSwitchOffIsNoStep) {
  // GIVEN no residual feedthrough, but the NCO (whose frame the quadratures
  // are in) turns 3e-3 rad away after the switch-off, as the PLL does when
  // the measured phase steps: in the NCO's frame X moves by 3e-3 V
  EdgeFeed feed;
  feed.nco_turn_rad = 3e-3;
  PumpEdgeCheck c(feed.cfg);
  feed.run(c, 200, 100);
  // THEN in the edge's fixed frame there is no step (4 sigma)
  LONGS_EQUAL(1, c.status().edges);
  const double sigma = sigma_r_one_edge(feed.cfg);
  DOUBLES_EQUAL(0.0, c.status().x_re, 4.0 * sigma);
  DOUBLES_EQUAL(0.0, c.status().x_im, 4.0 * sigma);
  DOUBLES_EQUAL(0.0, c.status().y_re, 4.0 * sigma);
  DOUBLES_EQUAL(0.0, c.status().y_im, 4.0 * sigma);
  CHECK(c.status().verdict == PumpEdgeVerdict::consistent);
}

TEST(PumpEdgeCheck, APumpThatSwingsRowToRowIsWeightedAsTheLineWeightsItsRows) {
  // GIVEN r_x = 2e-4 V/V while the pump swings between 0.3 and 5.7 V from
  // row to row (the AGC's chatter early in operation)
  EdgeFeed feed;
  feed.pump_swing = 0.9;
  feed.r_x = std::polar(2e-4, -0.4);
  PumpEdgeCheck c(feed.cfg);
  feed.run(c, 200, 100);
  // THEN r is read back (4 sigma of the one-edge noise, at the weighted
  // pump's amplitude, which is within 2x of the mean)
  const double sigma = 2.0 * sigma_r_one_edge(feed.cfg);
  DOUBLES_EQUAL(feed.r_x.real(), c.status().x_re, 4.0 * sigma);
  DOUBLES_EQUAL(feed.r_x.imag(), c.status().x_im, 4.0 * sigma);
  DOUBLES_EQUAL(0.0, c.status().y_re, 4.0 * sigma);
  CHECK(c.status().verdict == PumpEdgeVerdict::step);
}

TEST(PumpEdgeCheck, TheEdgesScatterAsTheirNoiseSaysUnlessTheResidualMovesBetweenThem) {
  // GIVEN 16 edges of noise alone: the mean's sigma from the edges' scatter
  // (60 degrees of freedom: +-9 % of sd) is the stated sigma
  EdgeFeed feed;
  PumpEdgeCheck c(feed.cfg);
  CHECK_EQUAL(0.0, c.status().scatter_v_per_v);
  for (int i = 0; i < 16; ++i)
    feed.run(c, 200, 100);
  LONGS_EQUAL(16, c.status().edges);
  DOUBLES_EQUAL(c.status().sigma_v_per_v, c.status().scatter_v_per_v,
                0.3 * c.status().sigma_v_per_v);
  // GIVEN x_re alternating between +-10 sigma of one edge: the pooled
  // chi^2 over 60 degrees of freedom is ~16 x 100 + 60, so the scatter is
  // sqrt(1660 / 60) = 5.3x the mean's sigma
  PumpEdgeCheck moving(feed.cfg);
  const double one = sigma_r_one_edge(feed.cfg);
  for (int i = 0; i < 16; ++i) {
    feed.r_x = {(i % 2 ? 10.0 : -10.0) * one, 0.0};
    feed.run(moving, 200, 100);
  }
  DOUBLES_EQUAL(5.3, moving.status().scatter_v_per_v / moving.status().sigma_v_per_v, 0.8);
}

TEST(PumpEdgeCheck, ItSaysHowLongTheCorrectionItReadThroughHasBeenInForce) {
  EdgeFeed feed;
  PumpEdgeCheck c(feed.cfg);
  // GIVEN 300 rows of 10 ms from t = 0
  feed.run(c, 200, 100);
  DOUBLES_EQUAL(299 * feed.row_s, c.status().in_force_s, 1e-9);
  // WHEN the correction changes (reset) and 300 more rows come
  c.reset();
  DOUBLES_EQUAL(0.0, c.status().in_force_s, 0.0);
  feed.run(c, 200, 100);
  // THEN from the first row after the change
  DOUBLES_EQUAL(299 * feed.row_s, c.status().in_force_s, 1e-9);
}

TEST(PumpEdgeCheck, AnEdgesSigmaIsTheSpreadOfItsReadingUnderTheDemodulatorsNoise) {
  // GIVEN 100 single edges of noise alone, the rows' noise the decimator's
  // (successive rows share input samples)
  EdgeFeed feed;
  double sum_sq = 0.0;
  double sigma_sum = 0.0;
  constexpr int kEdges = 100;
  for (int i = 0; i < kEdges; ++i) {
    PumpEdgeCheck c(feed.cfg);
    feed.run(c, 200, 100);
    LONGS_EQUAL(1, c.status().edges);
    const PumpEdgeStatus& s = c.status();
    sum_sq += s.x_re * s.x_re + s.x_im * s.x_im + s.y_re * s.y_re + s.y_im * s.y_im;
    sigma_sum += s.sigma_v_per_v;
  }
  // THEN the stated sigma is the readings' spread (400 parts: +-3.5 % of
  // sd); read as from independent rows it was 1 / sqrt(2.3233) = 0.66 of it
  const double spread = std::sqrt(sum_sq / (4.0 * kEdges));
  const double stated = sigma_sum / kEdges;
  DOUBLES_EQUAL(1.0, stated / spread, 0.12);
  DOUBLES_EQUAL(sigma_r_one_edge(feed.cfg), stated, 0.1 * stated);
}

TEST(PumpEdgeCheck, TheAgcsChatterCarryingAFeedthroughIsNotCountedAsNoise) {
  // GIVEN one edge of the same noise twice, the pump swinging between 0.3
  // and 5.7 V from row to row, once with r_x = 2e-4 V/V (2e-4 x 2.7 V of
  // swing in the rows, 18x the rows' noise) and once with none
  EdgeFeed with;
  with.pump_swing = 0.9;
  with.r_x = {2e-4, 0.0};
  EdgeFeed without;
  without.pump_swing = 0.9;
  PumpEdgeCheck a(with.cfg);
  PumpEdgeCheck b(without.cfg);
  with.run(a, 200, 100);
  without.run(b, 200, 100);
  // THEN both state the noise's sigma (the feedthrough follows the pump: it
  // is no misfit; counted as one, the sigma was 4.5x larger)
  DOUBLES_EQUAL(b.status().sigma_v_per_v, a.status().sigma_v_per_v,
                0.05 * b.status().sigma_v_per_v);
  DOUBLES_EQUAL(2e-4, a.status().x_re, 4.0 * a.status().sigma_v_per_v);
}

TEST(PumpEdgeCheck, APumpLeavingZeroWithinTheRowsBendsTheWaveAndTheStepIsReadThroughTheBend) {
  // GIVEN r_x = 2e-4 V/V, the pump at 0 until 20 rows before the last
  // pump-on row and at 3 V from then, the vibration growing by 3e-6 per V^2 and
  // row while it runs (2.7e-5 V per row at 1 V: the parametric pump at its
  // limit leaving the AGC's lower one)
  EdgeFeed feed;
  feed.r_x = {2e-4, 0.0};
  feed.pump_rise_row = -20.0;
  feed.growth_per_v2_row = 3e-6;
  PumpEdgeCheck c(feed.cfg);
  feed.run(c, 200, 100);
  // THEN r is read within 3 of its stated sigmas (a line through the bent
  // rows read x_re 1.38e-4, 4 of its sigmas off though the bend's misfit
  // had tripled them), y none
  const PumpEdgeStatus& s = c.status();
  LONGS_EQUAL(1, s.edges);
  DOUBLES_EQUAL(2e-4, s.x_re, 3.0 * s.sigma_v_per_v);
  DOUBLES_EQUAL(0.0, s.x_im, 3.0 * s.sigma_v_per_v);
  DOUBLES_EQUAL(0.0, s.y_re, 3.0 * s.sigma_v_per_v);
  DOUBLES_EQUAL(0.0, s.y_im, 3.0 * s.sigma_v_per_v);
}
