// SPDX-License-Identifier: MIT
#include <estimator/drift.hpp>
#include <estimator/estimator.hpp>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "synthetic_decay.hpp"
#include "window_runner.hpp"

#include "support/cpputest.hpp"

using namespace hrg::est;
using namespace hrg::est::test;

namespace {
// 16 noise-free 1 s windows of the model p, one every 10 s, spread evenly
// over the 4theta circle: enough for the estimator to accept p.
void fold_spread_windows(Estimator& est, const ParamVector& p, std::mt19937_64& rng) {
  const SyntheticDecay gen{p, 0.554, 0.0};
  for (int k = 0; k < 16; ++k) {
    DecayState s{10.0 * k, 1.0, 0.0, 0.05 + k * M_PI / 32};
    est.begin_window(s.t_s);
    for (int i = 0; i < 1000; ++i) {
      gen.step(s, 1e-3);
      est.add_sample(gen.measure(s, 0.0, rng));
    }
    CHECK(est.end_window() == Status::ok);
  }
}
}  // namespace

TEST_GROUP(DriftModel) { ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180); };

TEST(DriftModel, ResonatorDriftIsEquation6WithEquation7AsItsFirstOrder) {
  const double nu_dmu = 0.05 * p(kNu), dw = M_PI * 5e-4;
  const double th_mu = 12 * M_PI / 180, th_w = 31 * M_PI / 180;
  // q = 0: D = nu dmu sin4(th - th_mu) = dnu_C sin4th - dnu_S cos4th
  DOUBLES_EQUAL(p(kDnuC), resonator_drift_rad_s(p, M_PI / 8, 0.0), 1e-18);
  DOUBLES_EQUAL(-p(kDnuS), resonator_drift_rad_s(p, 0.0, 0.0), 1e-18);
  for (double th : {0.0, 0.37, 1.1}) {
    for (double q : {0.0, 0.05, -0.2}) {
      const double eq6 = (nu_dmu * std::sin(4 * (th - th_mu)) * (1 + q * q) -
                          2 * q * dw * std::cos(4 * (th - th_w))) /
                         (1 - q * q);
      const double eq7 =
          nu_dmu * std::sin(4 * (th - th_mu)) - 2 * dw * std::cos(4 * (th - th_w)) * q;
      const double d = resonator_drift_rad_s(p, th, q);
      DOUBLES_EQUAL(eq6, d, 1e-18);
      // eq. 7 is the first order in q: they differ by O(q^2) of the terms
      DOUBLES_EQUAL(eq7, d, 2.5 * q * q * (nu_dmu + 2 * std::abs(q) * dw) + 1e-18);
    }
  }
}

TEST(DriftModel, TheCorrectionNeverJumpsWhenTheModelChanges) {
  DriftCompensator comp{0.554};
  comp.set_model(p);
  for (int i = 0; i < 1000; ++i)
    comp.step(0.3, 0.0, 0.0, 1e-3);
  const double before = comp.correction_rad();
  const double rate_before = comp.rate_rad_s();
  ParamVector other = p;
  other(kDnuC) *= -3.0;
  comp.set_model(other);
  comp.step(0.3, 0.0, 0.0, 1e-3);
  const double rate_after = comp.rate_rad_s();
  CHECK(std::abs(rate_after - rate_before) > 1e-5);
  // The first step after the change moves by the mean of the two rates times dt only.
  DOUBLES_EQUAL(before + 0.5e-3 * (rate_before + rate_after), comp.correction_rad(), 1e-15);
}

TEST(DriftModel, CompensationCancelsTheResonatorDriftOfAPrecessingPattern) {
  // GIVEN a pattern under eq. 7 drift at zero input rate with a_B/a_A = 0.02
  // held by the loops (theta' = D/2), the raw output -2 (th - th0)/K drifts
  const double K = 0.554;
  DriftCompensator comp{K};
  comp.set_model(p);
  double th = 0.1;
  const double q = 0.02;
  const double dt = 1e-3;
  for (int i = 0; i < 100000; ++i) {
    const double th_mid = th + 0.25 * dt * resonator_drift_rad_s(p, th, q);
    comp.step(th, q, 0.0, dt);
    th += 0.5 * dt * resonator_drift_rad_s(p, th_mid, q);
  }
  comp.step(th, q, 0.0, 0.0);
  const double raw = -2.0 * (th - 0.1) / K;
  // THEN raw drift is large (order 1e-2 rad in 100 s) and the compensated one is
  // zero to the integration error
  CHECK(std::abs(raw) > 1e-3);
  DOUBLES_EQUAL(0.0, raw + comp.correction_rad(), 1e-8);
}

TEST_GROUP(ControlDrift){};

TEST(ControlDrift, Equation23FromThePumpPhaseErrorAndQuadratureEffort) {
  // GIVEN the identified resonator, a pump with phase error eps = 20 mrad whose
  // B projection carries a gap term (eq. 27) and a quadrature forcer with
  // known parts; a_A is held by the AGC and a_B ramps slowly
  const ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  ControlDriftEstimator est;
  est.set_model(p);
  const double eps = 0.02, eps_gap = 1e-3, th = 0.4;
  const double c4 = std::cos(4 * th), s4 = std::sin(4 * th);
  const double d = p(kDnuC) * c4 + p(kDnuS) * s4;
  const double g = p(kDwC) * s4 - p(kDwS) * c4;
  double aA = 1.0, aB = 0.01, truth = 0;
  const double nu = p(kNu), dt = 1e-3;
  for (int i = 0; i < 20000; ++i) {
    const double t = i * dt;
    const double aB_dot = 2e-4;  // slow ramp the estimator must differentiate
    // AGC: in-phase pump force on A holds a_A.
    const double fA_sin = (nu + d) * aA + g * aB;
    const double aPhiA = fA_sin / std::cos(eps);
    // Pump on B: nu-matched plus the gap term eps_gap a_A, same phase error.
    const double aPhiB = nu * aB + eps_gap * nu * aA;
    // Quadrature forcer supplies the rest of a_B' (in-phase part) and a known out-of-phase part.
    const double qs = aB_dot + (nu - d) * aB - g * aA - aPhiB * std::cos(eps);
    const double qc = 3e-6;
    ControlDriftEstimator::Sample s{t, aA, aB, th, eps, qs, qc};
    est.add_sample(s);
    // eq. 23 with the total B force cos part.
    truth = -(aPhiB * std::sin(eps) + qc) / aA + (aB / aA) * aPhiA * std::sin(eps) / aA;
    aB += aB_dot * dt;
  }
  // THEN the estimate matches eq. 23 (which is of order 1e-6 rad/s here)
  CHECK(est.valid());
  CHECK(std::abs(truth) > 1e-6);
  DOUBLES_EQUAL(truth, est.d_phi_rad_s(), 0.01 * std::abs(truth));
  // AND with an ideal ring on an isotropic resonator (a_PhiA sin dphi = nu a_A,
  // a_PhiB sin dphi = nu a_B, the same phase error on both) eq. 29 gives zero
  ParamVector iso = ParamVector::Zero();
  iso(kNu) = nu;
  ControlDriftEstimator ideal;
  ideal.set_model(iso);
  aB = 0.01;
  for (int i = 0; i < 5000; ++i) {
    const double aPhiB = nu * aB / std::cos(eps);
    const double qs = nu * aB - aPhiB * std::cos(eps);
    ideal.add_sample({i * dt, aA, aB, th, eps, qs, 0.0});
  }
  CHECK(ideal.valid());
  DOUBLES_EQUAL(0.0, ideal.d_phi_rad_s(), 1e-12);
}

TEST(ControlDrift, EstimatorFacadeGivesNoDriftBeforeAModel) {
  Estimator::Config cfg;
  Estimator est{cfg};
  // No model yet: no drift at all.
  DOUBLES_EQUAL(0.0, est.drift_rate_rad_s(0.2, 0.0), 0.0);
  DOUBLES_EQUAL(0.0, est.d_phi_rad_s(0.2), 0.0);
  const double th = est.least_covered_theta_rad();
  CHECK(th >= 0 && th < M_PI / 2);
}

TEST(ControlDrift, EstimatorDriftAndDPhiIntegrateToTheirCorrections) {
  // GIVEN an estimator with an accepted model (16 noise-free windows)
  const ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  Estimator::Config cfg;
  Estimator est{cfg};
  std::mt19937_64 rng(1);
  fold_spread_windows(est, p, rng);
  CHECK(est.solve_and_accept().accepted());
  CHECK(est.has_model());
  // AND the loops show a constant D_Phi: a quadrature forcer with an
  // out-of-phase part qc at a_A = 1, a_B = 0 gives D_Phi = -qc
  const double qc = 2e-6, th = 0.3;
  const double c4 = std::cos(4 * th), s4 = std::sin(4 * th);
  const double g = p(kDwC) * s4 - p(kDwS) * c4;
  for (int i = 0; i < 3000; ++i) {
    // in-phase forcer part cancels the split's quadrature growth: a_B stays 0
    est.add_control_sample({200.0 + i * 1e-3, 1.0, 0.0, th, 0.0, -g, qc});
  }
  DOUBLES_EQUAL(-qc, est.d_phi_rad_s(th), 1e-3 * qc);
  // WHEN the output's integrator (the firmware's AngleOutput uses this one)
  // takes D = D_nu + D_w + D_Phi for 1 s (excitation on), then D_nu + D_w
  // for 1 s (excitation off: the firmware leaves D_Phi out)
  const double dnu_rate = est.drift_rate_rad_s(th, 0.0) / 0.554;
  DriftCompensator out{0.554};
  for (int i = 0; i < 1000; ++i)
    out.integrate(est.drift_rate_rad_s(th, 0.0) + est.d_phi_rad_s(th), 1e-3);
  const double with_exc = out.correction_rad();
  for (int i = 0; i < 1000; ++i)
    out.integrate(est.drift_rate_rad_s(th, 0.0), 1e-3);
  const double without = out.correction_rad() - with_exc;
  // THEN the corrections are the rates / K times 1 s (the trapezoid of the
  // step between the two adds half a period of D_Phi/K)
  DOUBLES_EQUAL((dnu_rate - qc / 0.554) * 1.0, with_exc, 1e-3 * qc);
  DOUBLES_EQUAL(dnu_rate * 1.0, without, 1e-3 * qc + 0.5e-3 * qc / 0.554);
}

TEST(ControlDrift, EstimatorKeepsNoModelFromIllConditionedWindows) {
  const ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  SyntheticDecay gen{p, 0.554, 0.0};
  Estimator::Config cfg;
  Estimator est{cfg};
  std::mt19937_64 rng(1);
  for (int k = 0; k < 16; ++k) {
    DecayState s{10.0 * k, 1.0, 0.0, 0.3};
    est.begin_window(s.t_s);
    for (int i = 0; i < 1000; ++i) {
      gen.step(s, 1e-3);
      est.add_sample(gen.measure(s, 2e-5, rng));
    }
    est.end_window();
  }
  CHECK(est.solve_and_accept().status == Status::ill_conditioned);
  CHECK_FALSE(est.has_model());
  // an aborted window adds nothing
  const double windows = est.normal_equations().windows();
  est.begin_window(1000.0);
  DecayState s{1000.0, 1.0, 0.0, 0.7};
  for (int i = 0; i < 500; ++i) {
    gen.step(s, 1e-3);
    est.add_sample(gen.measure(s, 2e-5, rng));
  }
  est.abort_window();
  CHECK(est.end_window() == Status::not_in_window);
  DOUBLES_EQUAL(windows, est.normal_equations().windows(), 0.0);
  DOUBLES_EQUAL(0.0, est.drift_rate_rad_s(0.3, 0.0), 0.0);
  CHECK(est.conditioning().kappa_2 > cfg.ls.max_kappa_2);
  // the scheduler is pointed away from the one covered bin
  CHECK(coverage_bin(est.least_covered_theta_rad()) != coverage_bin(0.3));
}

TEST(ControlDrift, PumpGapHarmonicsComeOutOfThePumpEffortOnSyntheticDecay) {
  // GIVEN eq. 3 with the ring pump of eqs. 25-27: a_A' = (-nu - dnu(th) +
  // c V0^2 cos(eps) (1 + e_p cos4th + e_q sin4th)) a_A, the pattern turning at
  // 0.2 rad/s, V0 near the balance with a 2 % ripple (no noise)
  const ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  const double c = 3.49e-4, e_p = 0.01, e_q = -0.004, eps = 0.05;
  PumpDriftEstimator est;
  est.set_model(p);
  double aA = 1.0, th = 0.0;
  const double dt = 1e-3;
  bool all_taken = true;
  for (int i = 0; i < 60000; ++i) {
    const double t = i * dt;
    const double c4 = std::cos(4 * th), s4 = std::sin(4 * th);
    const double dnu = p(kDnuC) * c4 + p(kDnuS) * s4;
    // The AGC keeps the mean balance; its ripple leaves a_A moving a little.
    const double v0 = std::sqrt(p(kNu) / (c * std::cos(eps))) * (1.0 + 0.02 * std::sin(0.7 * t));
    const double w = v0 * v0 * std::cos(eps);
    all_taken = est.add_sample({t, aA, 0.0, th, eps, 0, 0, v0}) && all_taken;
    aA *= std::exp(dt * (-p(kNu) - dnu + c * w * (1 + e_p * c4 + e_q * s4)));
    th += 0.2 * dt;
  }
  CHECK(all_taken);
  CHECK(est.valid());
  const Eigen::Vector3d b = est.coefficients();
  // THEN (c, c e_p, c e_q) are recovered and D_Phi = w (b2 cos4th - b1 sin4th)
  DOUBLES_EQUAL(c, b(0), 1e-4 * c);
  DOUBLES_EQUAL(e_p, b(1) / b(0), 1e-4);
  DOUBLES_EQUAL(e_q, b(2) / b(0), 1e-4);
  // AND a break between segments (a free-decay window) keeps the fit
  est.restart();
  CHECK(est.valid());
}

TEST(ControlDrift, AKnownGapGivesThePumpsDriftAtTheAgcBalance) {
  // GIVEN the resonator identified and a gap harmonic from a calibration
  // (1/d0^3 ~ 1 + eps_p cos4th + eps_q sin4th; G's half-harmonics on the wave)
  const ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  const double eps_p = 0.02, eps_q = 0.01;
  for (double th = 0.0; th < M_PI / 2; th += M_PI / 28) {
    const double c4 = std::cos(4 * th), s4 = std::sin(4 * th);
    // THEN with the pump holding a_A (eq. 3: a_A' = 0), the pump's growth
    // rate balances the damping along the wave, kappa (1 + eps_p/2 c4 +
    // eps_q/2 s4) = nu + dnu(th), and the drift is the pump's force across
    // the wave: D_Phi = kappa (eps_q/2 c4 - eps_p/2 s4), ~ nu |eps| / 2.
    const double kappa =
        (p(kNu) + p(kDnuC) * c4 + p(kDnuS) * s4) / (1.0 + 0.5 * (eps_p * c4 + eps_q * s4));
    const double d = known_gap_drift_rad_s(p, eps_p, eps_q, th);
    DOUBLES_EQUAL(kappa * 0.5 * (eps_q * c4 - eps_p * s4), d, 1e-15);
    CHECK(std::fabs(d) <= 1.1 * p(kNu) * std::hypot(eps_p, eps_q) / 2.0);
  }
  // AND the Estimator uses it only with a model, and not at all once zero
  Estimator::Config cfg;
  cfg.gap = {eps_p, eps_q};
  Estimator e(cfg);
  DOUBLES_EQUAL(0.0, e.pump_d_phi_rad_s(0.3), 0.0);
  e.set_known_gap({0.0, 0.0});
  CHECK_FALSE(e.known_gap().known());
}

TEST(ControlDrift, AKnownGapTakesThePumpsGrowthFromTheWavesAmplitude) {
  // GIVEN the resonator identified, a known gap harmonic and the wave growing
  // at g = 0.02 1/s with the excitation on (the AGC making up what a
  // free-decay window lost), sampled at 1 kHz, with a quadrature ratio q
  const ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  const double eps_p = 0.02, eps_q = 0.01, th = 0.3, q = 0.01, k = 1.1, g = 0.02;
  KnownGapDrift gap;
  const double a0 = 1.0;
  double integral = 0.0;
  double d_first = 0.0;
  for (int i = 0; i <= 1000; ++i) {
    const double t = 10.0 + 1e-3 * i;
    const double d = gap.step(p, eps_p, eps_q, t, th, a0 * std::exp(g * (t - 10.0)), q, k);
    if (i == 0) d_first = d;
    if (i > 0) integral += d * 1e-3;
  }
  // THEN the first sample after a start has no growth: the balance of eq. 20
  // with the damping scale and the split term, kappa (1 + eps_p/2 c4 +
  // eps_q/2 s4) = k (nu + dnu(th)) + (dw_C s4 - dw_S c4) q
  const double c4 = std::cos(4 * th), s4 = std::sin(4 * th);
  const double f = 0.5 * (eps_q * c4 - eps_p * s4) / (1.0 + 0.5 * (eps_p * c4 + eps_q * s4));
  const double decay =
      k * (p(kNu) + p(kDnuC) * c4 + p(kDnuS) * s4) + (p(kDwC) * s4 - p(kDwS) * c4) * q;
  DOUBLES_EQUAL(decay * f, d_first, 1e-15);
  DOUBLES_EQUAL(known_gap_drift_rad_s(p, eps_p, eps_q, th, 0.0, q, k), d_first, 0.0);
  // AND over the second it adds the pump's extra work: (decay + g) f per
  // second, the growth exact as the change of ln a_A
  DOUBLES_EQUAL((decay + g) * f, integral, 1e-12);
  DOUBLES_EQUAL(g, gap.growth_per_s(), 1e-9);
  // AND a gap in the samples (a free-decay window: the amplitude fell with
  // no pump) starts afresh at growth 0, as does a bad amplitude
  const double after = gap.step(p, eps_p, eps_q, 12.0, th, 0.5, q, k);
  DOUBLES_EQUAL(decay * f, after, 1e-15);
  DOUBLES_EQUAL(0.0, gap.step(p, eps_p, eps_q, 12.001, th, 0.0, q, k), 0.0);
}

namespace {
// The ring pump on a turning pattern (eq. 3 with eqs. 25-27), as the chain
// delivers it: every `window_s` the excitation is off (the fit restarts) and
// the AGC then pumps hard while the amplitude catches up. The sample at row i
// carries the pump written then (ChainOutputs::pump_v, for the next block);
// it acts on the resonator `lag` rows later.
struct PumpedRing {
  ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  double c = 3.49e-4, e_p = 0.01, e_q = -0.004, eps = 0.05;
  double dt = 1e-3;
  int lag = 3;
  double window_s = 5.0;
  double turn_rad_s = 0.2;
  double t = 0.0, a_A = 1.0, th = 0.0;
  // A thermal damping: the whole damping times k = 1 + thermal_share cos(thermal_rad_s t)
  // (beta times the temperature's swing); the samples carry k when it is known.
  double thermal_share = 0.0, thermal_rad_s = 0.0;
  bool thermal_known = true;
  std::vector<double> w_written;

  double damping_scale() const { return 1.0 + thermal_share * std::cos(thermal_rad_s * t); }
  double pump_v() const {
    const double balance = std::sqrt(damping_scale() * p(kNu) / (c * std::cos(eps)));
    const double since_window_s = std::fmod(t, window_s);
    return balance * (1.0 + 0.5 * std::exp(-since_window_s / 0.3) + 0.02 * std::sin(0.7 * t));
  }
  // Runs for duration_s, feeding `est`; false if a sample was refused.
  template <class Sink>
  bool run(double duration_s, Sink&& est) {
    bool all_taken = true;
    const double t_end = t + duration_s;
    double next_window = std::floor(t / window_s) * window_s + window_s;
    while (t < t_end) {
      if (t >= next_window) {
        est.restart();
        next_window += window_s;
      }
      const double v0 = pump_v();
      w_written.push_back(v0 * v0 * std::cos(eps));
      const double k = damping_scale();
      all_taken =
          est.add_sample({t, a_A, 0.0, th, eps, 0, 0, v0, thermal_known ? k : 1.0}) && all_taken;
      const std::size_t n = w_written.size();
      const double w_acting = n > static_cast<std::size_t>(lag) ? w_written[n - 1 - lag] : 0.0;
      const double c4 = std::cos(4 * th), s4 = std::sin(4 * th);
      const double dnu = p(kDnuC) * c4 + p(kDnuS) * s4;
      a_A *= std::exp(dt * (-k * (p(kNu) + dnu) + c * w_acting * (1 + e_p * c4 + e_q * s4)));
      th += turn_rad_s * dt;
      t += dt;
    }
    return all_taken;
  }
};
// Two fits fed the same samples.
struct Both {
  PumpDriftEstimator &a, &b;
  void restart() {
    a.restart();
    b.restart();
  }
  bool add_sample(const PumpDriftEstimator::Sample& s) {
    const bool ok_a = a.add_sample(s);
    return b.add_sample(s) && ok_a;
  }
};

// The estimator's control samples with white noise on the measured
// amplitude (the batch fits scatter as on a real pickoff).
struct NoisyAmplitude {
  Estimator& e;
  std::mt19937_64& rng;
  std::normal_distribution<double>& n;
  void restart() { e.restart_control(); }
  bool add_sample(PumpDriftEstimator::Sample s) {
    s.a_A_v += n(rng);
    return e.add_control_sample(s);
  }
};
}  // namespace

TEST(ControlDrift, PumpFitIntegratesThePumpThatActedOnTheRow) {
  // GIVEN the chain's pump acting 3 rows after it is written, and the AGC's
  // recovery after each free-decay window
  PumpedRing ring;
  PumpDriftEstimator::Config aligned_cfg;
  aligned_cfg.pump_lag_samples = ring.lag;
  PumpDriftEstimator aligned(aligned_cfg);
  PumpDriftEstimator as_written;  // the pump of the sample, 3 ms early
  aligned.set_model(ring.p);
  as_written.set_model(ring.p);
  CHECK(ring.run(60.0, Both{aligned, as_written}));
  CHECK(aligned.valid());
  CHECK(as_written.valid());
  // THEN the fit of the pump that acted gives (c, c e_p, c e_q)
  const Eigen::Vector3d b = aligned.coefficients();
  DOUBLES_EQUAL(ring.c, b(0), 1e-4 * ring.c);
  DOUBLES_EQUAL(ring.e_p, b(1) / b(0), 1e-4);
  DOUBLES_EQUAL(ring.e_q, b(2) / b(0), 1e-4);
  // AND the pump as written (3 ms early) reads the recovery as more pump
  // gain, outside that tolerance (2.5e-4 of c here; 1.7e-3 in the simulated
  // chain, where the recovery is slower)
  const Eigen::Vector3d bw = as_written.coefficients();
  std::printf("\n  pump gain: aligned %.6e, as written %.6e (true %.6e)\n", b(0), bw(0), ring.c);
  CHECK(bw(0) - ring.c > 1e-4 * ring.c);
}

TEST(ControlDrift, PumpFitStaysInForceWhenRowsPileUpAtOneAngle) {
  // GIVEN a fit conditioned on a turning pattern (the firmware's 3x3 limit)
  PumpedRing ring;
  PumpDriftEstimator::Config cfg;
  cfg.pump_lag_samples = ring.lag;
  cfg.max_kappa_2 = 10.0;
  PumpDriftEstimator est(cfg);
  PumpDriftEstimator::Config forgetful_cfg = cfg;
  forgetful_cfg.forgetting_time_s = 30.0;
  PumpDriftEstimator forgetful(forgetful_cfg);
  est.set_model(ring.p);
  forgetful.set_model(ring.p);
  CHECK(ring.run(40.0, Both{est, forgetful}));
  CHECK(est.valid());
  CHECK(forgetful.valid());
  // WHEN the pattern then stays at one angle for 10 min (the parks; a
  // pattern at its equilibrium)
  ring.turn_rad_s = 0.0;
  CHECK(ring.run(600.0, Both{est, forgetful}));
  // THEN kappa_2 of the 3x3 grows past the limit (one combination informed
  // more), yet the fit keeps what it knew and stays valid, at the truth
  CHECK(est.kappa_2() > cfg.max_kappa_2);
  CHECK(est.valid());
  const Eigen::Vector3d b = est.coefficients();
  DOUBLES_EQUAL(ring.e_p, b(1) / b(0), 1e-4);
  DOUBLES_EQUAL(ring.e_q, b(2) / b(0), 1e-4);
  // AND with forgetting the other combinations fade: no longer valid
  CHECK_FALSE(forgetful.valid());
}

TEST(ControlDrift, ALostPumpDriftIsReported) {
  // GIVEN an estimator with an accepted model (16 noise-free windows) whose
  // pump fit forgets in 30 s
  const ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  Estimator::Config cfg;
  cfg.pump.pump_lag_samples = 3;
  cfg.pump.forgetting_time_s = 30.0;
  cfg.pump.max_kappa_2 = 10.0;
  Estimator est{cfg};
  std::mt19937_64 rng(1);
  fold_spread_windows(est, p, rng);
  CHECK(est.solve_and_accept().accepted());
  // AND the pump with a gap harmonic on a turning pattern, the amplitude
  // read with 1e-6 V of noise (the batch fits scatter)
  PumpedRing ring;
  ring.p = est.model();
  ring.t = 200.0;
  std::normal_distribution<double> noise(0.0, 1e-6);
  NoisyAmplitude sink{est, rng, noise};
  CHECK(ring.run(400.0, sink));
  // THEN its D_Phi is in force and nothing is lost
  CHECK(est.pump_drift().usable());
  CHECK(est.pump_d_phi_rad_s(0.3) != 0.0);
  CHECK_FALSE(est.pump_drift_lost());
  // WHEN the pattern stays at one angle until the fit has forgotten the others
  ring.turn_rad_s = 0.0;
  CHECK(ring.run(600.0, sink));
  // THEN the D_Phi it added is withdrawn and reported lost
  CHECK_FALSE(est.pump_drift().usable());
  DOUBLES_EQUAL(0.0, est.pump_d_phi_rad_s(0.3), 0.0);
  CHECK(est.pump_drift_lost());
}

namespace {
// The pump fit of a noisy turning pattern (1e-6 V on the amplitude) beside
// a known gap: the estimator with an accepted model and the gap given.
struct KnownGapTrial {
  ParamVector p = seed_params(12 * M_PI / 180, 31 * M_PI / 180);
  Estimator est{config()};
  static Estimator::Config config() {
    Estimator::Config cfg;
    cfg.pump.pump_lag_samples = 3;
    cfg.pump.max_kappa_2 = 10.0;
    return cfg;
  }
  // Runs the ring for duration_s; the gap fit's (b1, b2) and covariance.
  void run(const Estimator::Config::KnownGap& gap, double duration_s) {
    std::mt19937_64 rng(1);
    fold_spread_windows(est, p, rng);
    CHECK(est.solve_and_accept().accepted());
    est.set_known_gap(gap);
    PumpedRing ring;
    ring.p = est.model();
    ring.t = 200.0;
    std::normal_distribution<double> noise(0.0, 1e-6);
    CHECK(ring.run(duration_s, NoisyAmplitude{est, rng, noise}));
  }
  // The fit's eps_p and its sigma.
  void fit_eps_p(double& eps_p, double& sigma) const {
    Eigen::Vector2d g;
    Eigen::Matrix2d cov;
    CHECK(est.pump_drift().gap_fit(g, cov));
    const double b0 = est.pump_drift().coefficients()(0);
    eps_p = 2.0 * g(0) / b0;
    sigma = 2.0 * std::sqrt(cov(0, 0)) / b0;
  }
};
}  // namespace

TEST(ControlDrift, AKnownGapIsCheckedInTheUncertaintyOfBothMeasurements) {
  // GIVEN the ring's gap (eps_p, eps_q) = 2 (e_p, e_q) = (0.02, -0.008)
  // measured by a calibration 1e-4 off in eps_p with a sigma of 1.25e-4
  // (0.8 of its sigma: a fair draw), while the online fit of 400 s reads it
  // far more precisely (the Gregory gap + thermal damping row at seed 2: 0.7 of
  // the file's sigma, 14 of the fit's)
  const double off = 1.0e-4, sigma = 1.25e-4;
  PumpedRing ring;
  const double eps_p = 2.0 * ring.e_p, eps_q = 2.0 * ring.e_q;
  KnownGapTrial exact, weighed, wrong_sign;
  exact.run({eps_p + off, eps_q}, 400.0);
  weighed.run({eps_p + off, eps_q, sigma, sigma}, 400.0);
  wrong_sign.run({-eps_p, -eps_q, sigma, sigma}, 400.0);
  double fit = 0.0, fit_sigma = 0.0;
  weighed.fit_eps_p(fit, fit_sigma);
  std::printf("\n  online eps_p %.6f +- %.1e (true %.4f); the file's %.4f +- %.2e\n", fit,
              fit_sigma, eps_p, eps_p + off, sigma);
  // THEN the fit is at the truth (as PumpFitIntegratesThePumpThatActedOnTheRow)
  // and the file stands more than 6.5 of the fit's own sigmas from it (what
  // refuted it when its sigma was left out) ...
  DOUBLES_EQUAL(eps_p, fit, 2e-4);
  CHECK(fit_sigma < sigma / 10.0);
  CHECK(std::fabs(fit - eps_p - off) > 6.5 * fit_sigma);
  CHECK(exact.est.known_gap_refuted());
  // ... but within 1 of the difference's (both sigmas): the file's gap is kept
  CHECK_FALSE(weighed.est.known_gap_refuted());
  // AND a gap of the wrong sign (320 of the file's sigmas off) is still refuted
  CHECK(wrong_sign.est.known_gap_refuted());
}

TEST(ControlDrift, PumpFitTakesAKnownThermalDampingOutOfItsRows) {
  // GIVEN a thermal damping of 0.4 % (0.004 /degC over +-1 degC) whose swing
  // the pattern's turn follows (4 theta turning with the temperature's
  // cycle: the worst case of a slow sweep), the AGC balancing it
  PumpedRing known, unknown;
  for (PumpedRing* r : {&known, &unknown}) {
    r->thermal_share = 0.004;
    r->thermal_rad_s = 4.0 * r->turn_rad_s;
  }
  unknown.thermal_known = false;
  PumpDriftEstimator::Config cfg;
  cfg.pump_lag_samples = known.lag;
  PumpDriftEstimator with_k(cfg), without_k(cfg);
  with_k.set_model(known.p);
  without_k.set_model(unknown.p);
  CHECK(known.run(60.0, with_k));
  CHECK(unknown.run(60.0, without_k));
  // THEN with the damping scale in the samples (a calibration's thermal
  // model) the fit is at the truth, as without the effect ...
  const Eigen::Vector3d b = with_k.coefficients();
  DOUBLES_EQUAL(known.e_p, b(1) / b(0), 1e-4);
  DOUBLES_EQUAL(known.e_q, b(2) / b(0), 1e-4);
  // ... and without it the damping's swing reads as a gap harmonic in
  // phase with it: e_p off by the damping's share, -nu beta A / (c w) = -0.004
  // (the rows' known decay falls short where the damping is high)
  const Eigen::Vector3d u = without_k.coefficients();
  std::printf("\n  e_p with the thermal model %.5f, without %.5f (true %.4f)\n", b(1) / b(0),
              u(1) / u(0), known.e_p);
  DOUBLES_EQUAL(known.e_p - known.thermal_share, u(1) / u(0), 0.1 * known.thermal_share);
}
