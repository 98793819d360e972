// SPDX-License-Identifier: MIT
// Monte Carlo of the joint estimator against the averaged resonator model,
// and the drift model of eqs. 6/7/22 measured on the same model.
#include <estimator/drift.hpp>
#include <estimator/estimator.hpp>

#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Dense>

#include "averaged_runner.hpp"

#include "support/cpputest.hpp"

using namespace hrg::est;
using namespace hrg::est::test;
namespace sim = hrg::sim;

namespace {

constexpr int kWindows = 12;
constexpr double kWindowS = 2.5;

// Takes kWindows windows over the 4theta circle (ideal control between them:
// a_A = 1 V, a_B = 0 at each switch) with a 2 deg/s input rate.
template <typename Rng>
void take_windows(const sim::ResonatorParams& rp, double noise_v, Rng& rng, NormalEquations& ls,
                  double theta_offset) {
  sim::AveragedModel m(rp);
  m.set_rate_profile(sim::Profile::constant(2.0 * sim::kDegToRad));
  WindowAccumulator acc;
  for (int k = 0; k < kWindows; ++k) {
    m.set_time(100.0 * k);
    m.set_standing_wave(1.0, theta_offset + k * (M_PI / 2) / kWindows, 0.0, 0.4);
    acc.begin_window(m.time_s());
    free_decay_window(m, kWindowS, noise_v, rng, [&](const WaveSample& s) { acc.add_sample(s); });
    WindowContribution w;
    if (acc.end_window(w) == Status::ok) ls.add_window(w);
  }
}

}  // namespace

TEST_GROUP(MonteCarlo){};

TEST(MonteCarlo, JointEstimatorIsUnbiasedAndEfficientOnTheAveragedModel) {
  // GIVEN the seed's resonator (5 kHz, Q 5e6, dQ/Q 0.1, split 5e-4 Hz) and
  // 2.2e-5 V of white noise per quadrature; 300 seeds (the bias criterion
  // 0.2 sigma is 3.5 standard errors of the mean at this count)
  const sim::ResonatorParams rp;
  const ParamVector truth = truth_of(rp);
  constexpr int kSeeds = 300;
  ParamVector sum = ParamVector::Zero(), sum2 = ParamVector::Zero();
  ParamVector crb_sum = ParamVector::Zero(), cov_sum = ParamVector::Zero();
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::mt19937_64 rng(1000 + seed);
    NormalEquations ls;
    take_windows(rp, kQuadratureNoiseV, rng, ls, 0.02 + 0.001 * seed);
    const Solution s = ls.solve(Variant::joint);
    CHECK(s.accepted());
    const ParamVector e = s.p - truth;
    sum += e;
    sum2 += e.cwiseProduct(e);
    crb_sum += ls.cramer_rao_bound(kQuadratureNoiseV).diagonal();
    cov_sum += s.covariance.diagonal();
  }
  const ParamVector bias = sum / kSeeds;
  const ParamVector var = (sum2 - kSeeds * bias.cwiseProduct(bias)) / (kSeeds - 1);
  const ParamVector crb = crb_sum / kSeeds;
  const char* names[kParams] = {"nu", "dnu_C", "dnu_S", "dw_C", "dw_S"};
  std::printf("\nMonte Carlo, %d seeds, %d windows of %.1f s, noise %.2e V\n", kSeeds, kWindows,
              kWindowS, kQuadratureNoiseV);
  std::printf("  param   truth        bias         sigma        sqrt(CRB)    var/CRB  cov/CRB\n");
  for (int i = 0; i < kParams; ++i) {
    const double sigma = std::sqrt(var(i));
    std::printf("  %-6s %+.5e %+.4e %.4e %.4e %.3f    %.3f\n", names[i], truth(i), bias(i), sigma,
                std::sqrt(crb(i)), var(i) / crb(i), cov_sum(i) / kSeeds / crb(i));
    // THEN unbiased to 0.2 sigma and within 1.25x the Cramer-Rao bound
    CHECK(std::abs(bias(i)) < 0.2 * sigma);
    CHECK(var(i) < 1.25 * crb(i));
    // AND the reported covariance agrees with the bound (same information)
    DOUBLES_EQUAL(1.0, cov_sum(i) / kSeeds / crb(i), 0.05);
  }
}

TEST(MonteCarlo, SingleEffectVariantsRecoverTheirParametersOnTheAveragedModel) {
  std::mt19937_64 rng(5);
  sim::ResonatorParams damping_only;
  damping_only.split_hz = 0.0;
  damping_only.th_mu_rad = 0.2;
  NormalEquations ls1;
  take_windows(damping_only, 0.0, rng, ls1, 0.03);
  const Solution s1 = ls1.solve(Variant::damping_only);
  CHECK(s1.accepted());
  const ParamVector t1 = truth_of(damping_only);
  for (int i : {kNu, kDnuC, kDnuS})
    DOUBLES_EQUAL(t1(i), s1.p(i), 1e-4 * 0.05 * t1(kNu));

  sim::ResonatorParams split_only;
  split_only.dmu = 0.0;
  split_only.th_w_rad = 0.5;
  NormalEquations ls2;
  take_windows(split_only, 0.0, rng, ls2, 0.03);
  const Solution s2 = ls2.solve(Variant::split_only);
  CHECK(s2.accepted());
  const ParamVector t2 = truth_of(split_only);
  DOUBLES_EQUAL(t2(kNu), s2.p(kNu), 1e-4 * 0.05 * t2(kNu));
  for (int i : {kDwC, kDwS})
    DOUBLES_EQUAL(t2(i), s2.p(i), 1e-5 * split_only.half_split_rad_s());
}

TEST(MonteCarlo, AveragedModelDriftFollowsEquation6NotThePaperEquation22SplitTerm) {
  // GIVEN the averaged model with both effects and axes off zero, at rest,
  // free, a_B/a_A = q held at the start: D = 2 theta_A' (Omega = 0)
  sim::ResonatorParams rp;
  rp.th_mu_rad = 12 * sim::kDegToRad;
  rp.th_w_rad = 31 * sim::kDegToRad;
  const ParamVector p = truth_of(rp);
  double worst_eq6 = 0, worst_eq22 = 0;
  for (double q : {0.0, 0.05}) {
    for (int k = 0; k < 16; ++k) {
      const double th = k * (M_PI / 2) / 16 + 0.01;
      sim::AveragedModel m(rp);
      m.set_standing_wave(1.0, th, q, 0.0);
      const sim::WaveState w0 = m.wave();
      const double h = 1e-3;
      m.advance(h);
      const sim::WaveState w1 = m.wave();
      const double d_model = 2.0 * std::remainder(w1.theta_rad - w0.theta_rad, M_PI / 2) / h;
      const double qm = w0.a_B_v / w0.a_A_v;
      const double c4 = std::cos(4 * th), s4 = std::sin(4 * th);
      // the paper's eq. 22 as printed
      const double eq22 = (p(kDnuC) - 2 * qm * p(kDwC)) * s4 - (p(kDnuS) + 2 * qm * p(kDwS)) * c4;
      worst_eq6 = std::max(worst_eq6, std::abs(d_model - resonator_drift_rad_s(p, th, qm)));
      worst_eq22 = std::max(worst_eq22, std::abs(d_model - eq22));
    }
  }
  std::printf(
      "\nDrift on the averaged model: max |D - eq.6| = %.3e rad/s, max |D - eq.22| = %.3e rad/s\n",
      worst_eq6, worst_eq22);
  // THEN eq. 6 (with eq. 14's cos4(th - th_w)) holds to 1e-3 of nu dmu (the
  // residual is the O(h) growth of a_B over the 1 ms difference), while eq. 22's
  // split term is off by the order of 2 q dw
  CHECK(worst_eq6 < 1e-3 * 0.05 * p(kNu));
  CHECK(worst_eq22 > 0.5 * 2 * 0.05 * rp.half_split_rad_s());
}

namespace {

sim::ResonatorParams params_of(const ParamVector& p, sim::ResonatorParams r) {
  r.q = M_PI * r.f_hz / p(kNu);
  r.dmu = std::hypot(p(kDnuC), p(kDnuS)) / p(kNu);
  r.th_mu_rad = 0.25 * std::atan2(p(kDnuS), p(kDnuC));
  r.split_hz = std::hypot(p(kDwC), p(kDwS)) / M_PI;
  r.th_w_rad = 0.25 * std::atan2(p(kDwS), p(kDwC));
  return r;
}

// Noise-free a_A, a_B of one window (settled samples) for parameters p and
// initial amplitudes; same design as take_windows.
void window_trajectory(const sim::ResonatorParams& r, int k, double a_A0, double a_B0,
                       Eigen::VectorXd& out) {
  sim::AveragedModel m(r);
  m.set_rate_profile(sim::Profile::constant(2.0 * sim::kDegToRad));
  m.set_time(100.0 * k);
  m.set_standing_wave(a_A0, 0.02 + k * (M_PI / 2) / kWindows, a_B0, 0.4);
  sim::EnvelopeDrive off;
  m.set_drive(off);
  const int n = static_cast<int>(std::lround(kWindowS / 1e-3));
  out.resize(2 * (n - 19));
  int j = 0;
  for (int i = 1; i <= n; ++i) {
    m.advance(1e-3);
    if (i < 20) continue;  // the 20 ms settle time
    const sim::WaveState w = m.wave();
    out(j++) = w.a_A_v;
    out(j++) = w.a_B_v;
  }
}

}  // namespace

TEST(MonteCarlo, EstimatorBoundEqualsTheFisherInformationOfTheAmplitudes) {
  // GIVEN the Monte Carlo's window design on the averaged model, and the
  // Fisher information of the five parameters computed independently of the
  // estimator: central differences of the model's a_A(t), a_B(t) (white noise
  // sigma each), with each window's a_A0, a_B0 as nuisance (Schur complement).
  // The pattern angle is a known regressor and carries no information: the
  // input rate that moves it is unknown in operation.
  const sim::ResonatorParams rp;
  const ParamVector p = truth_of(rp);
  const double sigma = kQuadratureNoiseV;
  ParamMatrix fisher = ParamMatrix::Zero();
  for (int k = 0; k < kWindows; ++k) {
    Eigen::VectorXd plus, minus;
    Eigen::MatrixXd J;
    for (int c = 0; c < kParams + 2; ++c) {
      const double h = 1e-6;
      ParamVector pp = p, pm = p;
      double ap = 1.0, am = 1.0, bp = 0.0, bm = 0.0;
      if (c < kParams) {
        pp(c) += h;
        pm(c) -= h;
      } else if (c == kParams) {
        ap += h;
        am -= h;
      } else {
        bp += h;
        bm -= h;
      }
      window_trajectory(params_of(pp, rp), k, ap, bp, plus);
      window_trajectory(params_of(pm, rp), k, am, bm, minus);
      if (c == 0) J.resize(plus.size(), kParams + 2);
      J.col(c) = (plus - minus) / (2 * h);
    }
    const Eigen::MatrixXd f = J.transpose() * J / (sigma * sigma);
    const Eigen::MatrixXd g = f.topLeftCorner(kParams, kParams);
    const Eigen::MatrixXd cr = f.topRightCorner(kParams, 2);
    const Eigen::MatrixXd l = f.bottomRightCorner(2, 2);
    fisher += g - cr * l.ldlt().solve(cr.transpose());
  }
  const ParamMatrix crb_fisher = fisher.inverse();
  // WHEN the estimator takes the same windows (noise-free: its bound depends
  // on the regressors only)
  std::mt19937_64 rng(1);
  NormalEquations ls;
  take_windows(rp, 0.0, rng, ls, 0.02);
  const ParamMatrix crb = ls.cramer_rao_bound(sigma);
  std::printf(
      "\nCramer-Rao bound, estimator vs Fisher information of the model (sqrt, same units):\n");
  for (int i = 0; i < kParams; ++i) {
    std::printf("  %d: %.4e vs %.4e (ratio of variances %.4f)\n", i, std::sqrt(crb(i, i)),
                std::sqrt(crb_fisher(i, i)), crb(i, i) / crb_fisher(i, i));
    // THEN the estimator's bound is the model's bound (block means and the
    // first-order sensitivities cost < 1 %)
    DOUBLES_EQUAL(1.0, crb(i, i) / crb_fisher(i, i), 0.01);
  }
}

TEST_GROUP(ControlDriftOnAveragedModel) {
  sim::ResonatorParams rp;
  ParamVector p;
  void setup() override {
    rp.th_mu_rad = 12 * sim::kDegToRad;
    rp.th_w_rad = 31 * sim::kDegToRad;
    p = truth_of(rp);
  }
  // D - (D_nu + D_w) of the model at rest, from the angle change over h.
  double measured_d_phi(sim::AveragedModel & m, double th, double q) {
    m.set_rate_profile(sim::Profile::constant(0.0));
    m.set_standing_wave(1.0, th, q, 0.0);
    const sim::WaveState w0 = m.wave();
    const double h = 1e-4;
    m.advance(h);
    const double d = 2.0 * std::remainder(m.wave().theta_rad - w0.theta_rad, M_PI / 2) / h;
    return d - resonator_drift_rad_s(p, th, w0.a_B_v / w0.a_A_v);
  }
};

TEST(ControlDriftOnAveragedModel, PumpGapDriftIsIdentifiedFromThePumpEffortAndCompensated) {
  // GIVEN a ring pump with a 4theta gap non-uniformity (eps_p 0.02, eps_q 0.01),
  // locked 0.1 rad off its best phase (eps = pi/2 - 2 (phi_V - phi_A) = -0.2),
  // the pattern precessing at 50 deg/s input rate for 60 s, noise as usual
  sim::ElectrodeParams el;
  el.eps_p = 0.02;
  el.eps_q = 0.01;
  const double delta = 0.1, eps = -2 * delta;
  sim::AveragedModel m(rp, el);
  m.set_standing_wave(1.0, 0.1, 0.0, 0.0);
  m.set_rate_profile(sim::Profile::constant(50 * sim::kDegToRad));
  sim::EnvelopeDrive dr;
  dr.excitation = true;
  dr.pump_v = el.threshold_v(rp.omega_rad_s(), rp.nu_per_s()) / std::sqrt(std::cos(2 * delta));
  dr.pump_phase_rad = M_PI / 4 + delta;
  m.set_drive(dr);
  PumpDriftEstimator est;
  est.set_model(p);
  std::mt19937_64 rng(3);
  for (int i = 0; i < 60000; ++i) {
    m.advance(1e-3);
    const WaveSample s = measure(m, kQuadratureNoiseV, rng);
    CHECK(est.add_sample({s.t_s, s.a_A_v, s.a_B_v, s.theta_A_rad, eps, 0, 0, dr.pump_v}));
  }
  CHECK(est.valid());
  // THEN the pump gain and the gap harmonics come out of the pump effort:
  // c = k_pump / (8 w), b1/c = eps_p/2, b2/c = eps_q/2
  const Eigen::Vector3d c = est.coefficients();
  const double c_true = el.pump_gain_per_s2_v2 / (8 * rp.omega_rad_s());
  DOUBLES_EQUAL(c_true, c(0), 1e-3 * c_true);
  DOUBLES_EQUAL(0.01, c(1) / c(0), 2e-4);
  DOUBLES_EQUAL(0.005, c(2) / c(0), 2e-4);
  // AND D_Phi = kappa (eps_q/2 cos4th - eps_p/2 sin4th) matches the model's
  // extra drift at 16 parked angles (q = 0) to 1 % of its amplitude, which the
  // paper's eq. 29 (zero for equal phase errors) does not see at all
  double worst = 0, amplitude = 0;
  for (int k = 0; k < 16; ++k) {
    const double th = 0.013 + k * (M_PI / 2) / 16;
    const double truth = measured_d_phi(m, th, 0.0);
    amplitude = std::max(amplitude, std::abs(truth));
    worst = std::max(worst, std::abs(truth - est.d_phi_rad_s(th)));
  }
  std::printf("\nPump gap drift: amplitude %.3e rad/s, worst estimate error %.3e rad/s\n",
              amplitude, worst);
  CHECK(amplitude > 3e-5);
  CHECK(worst < 0.01 * amplitude);
}

TEST(ControlDriftOnAveragedModel, DepumpedQuadratureWaveDriftFollowsEquation23) {
  // GIVEN an ideal ring pump (no gap), 0.1 rad off its best phase, on an
  // isotropic resonator, with a_B/a_A = 0.05: the parametric pump damps the
  // quadrature wave B (dphi_B = dphi_A - pi), so eq. 23 gives
  // D_Phi = 2 nu q tan(eps), not the zero of eq. 29
  sim::ResonatorParams iso;
  iso.dmu = 0.0;
  iso.split_hz = 0.0;
  p = truth_of(iso);
  const double delta = 0.1, eps = -2 * delta, th = 0.3;
  sim::AveragedModel m(iso);
  sim::EnvelopeDrive dr;
  dr.excitation = true;
  dr.pump_v = sim::ElectrodeParams{}.threshold_v(iso.omega_rad_s(), iso.nu_per_s()) /
              std::sqrt(std::cos(2 * delta));
  dr.pump_phase_rad = M_PI / 4 + delta;
  m.set_drive(dr);
  m.set_max_step_s(1e-3);
  m.set_standing_wave(1.0, th, 0.05, 0.0);
  ControlDriftEstimator est;
  est.set_model(p);
  std::mt19937_64 rng(4);
  for (int i = 0; i < 3000; ++i) {
    m.advance(1e-3);
    const WaveSample s = measure(m, kQuadratureNoiseV, rng);
    est.add_sample({s.t_s, s.a_A_v, s.a_B_v, s.theta_A_rad, eps, 0, 0, dr.pump_v});
  }
  const sim::WaveState w = m.wave();
  const double q = w.a_B_v / w.a_A_v;
  sim::AveragedModel probe = m;
  const double truth = measured_d_phi(probe, w.theta_rad, q);
  std::printf(
      "\nDe-pumped quadrature drift: model %.4e, estimate %.4e, 2 nu q tan(eps) %.4e rad/s\n",
      truth, est.d_phi_rad_s(), 2 * iso.nu_per_s() * q * std::tan(eps));
  CHECK(std::abs(truth) > 1e-5);
  DOUBLES_EQUAL(truth, est.d_phi_rad_s(), 0.03 * std::abs(truth));
}
