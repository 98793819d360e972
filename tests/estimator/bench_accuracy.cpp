// SPDX-License-Identifier: MIT
// Accuracy benchmark: one hour of operation of the seed's resonator on the
// averaged model, with free-decay windows of 5.5 s every 60 s (9.2 %
// excitation-off time). Between windows ideal control holds a_A = 1 V and
// nulls a_B (the standing wave is re-imposed every 50 ms) while the pattern
// precesses under Omega(t) = 5 + 3 sin(2 pi t / 700 s) deg/s, which sweeps all
// 4theta. At the end the pattern is parked at 32 angles (Omega = 0) and the
// apparent rate -2 theta_A'/K is the raw bias; the compensated bias adds the
// estimator's D/K. Both are fitted with b + A sin4th + B cos4th (deg/h).
// Prints the figures; exits non-zero if the compensated ADB misses 0.05 deg/h.
#include <estimator/estimator.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <span>

#include <Eigen/Dense>

#include "averaged_runner.hpp"
#include "sim_run/analysis.hpp"

using namespace hrg::est;
using namespace hrg::est::test;
namespace sim = hrg::sim;

namespace {
constexpr double kRadSToDegH = 180.0 / M_PI * 3600.0;
constexpr double kHourS = 3600.0;
constexpr double kPeriodS = 60.0;
constexpr double kWindowS = 5.5;
constexpr double kChunkS = 0.05;
constexpr double kGoalDegH = 0.05;

using hrg::sim_run::BiasFit;

// IEEE 1431 fit b + A sin4th + B cos4th over the parked angles (deg/h).
template <std::size_t N>
BiasFit fit_parked(const double (&th)[N], const double (&y)[N]) {
  return hrg::sim_run::fit_bias_4theta(std::span<const double>(th), std::span<const double>(y));
}

// Angle-dependent part of the model error, deg/h of input rate.
double adb_error_deg_h(const ParamVector& est, const ParamVector& truth, double k) {
  return std::hypot(est(kDnuC) - truth(kDnuC), est(kDnuS) - truth(kDnuS)) / k * kRadSToDegH;
}
}  // namespace

struct HourResult {
  double raw_adb_deg_h, comp_adb_deg_h, converged_at_s, self_converged_at_s;
};

HourResult run_hour(uint64_t seed, bool verbose, double forgetting_time_s = 0.0) {
  const sim::ResonatorParams rp;
  const ParamVector truth = truth_of(rp);
  const double K = rp.angular_gain;
  sim::AveragedModel m(rp);
  m.set_rate_profile(
      sim::Profile::sine(3.0 * sim::kDegToRad, 1.0 / 700.0, 0.0).add_offset(5.0 * sim::kDegToRad));
  m.set_standing_wave(1.0, 0.1, 0.0, 0.0);
  sim::EnvelopeDrive off;
  off.excitation = false;
  m.set_drive(off);

  Estimator::Config cfg;
  cfg.ls.forgetting_time_s = forgetting_time_s;
  Estimator est{cfg};
  std::mt19937_64 rng(seed);

  double off_time_s = 0;
  double converged_at_s = -1, self_converged_at_s = -1, first_accept_s = -1;
  int windows = 0;
  while (m.time_s() < kHourS - 1e-9) {
    // Ideal control between windows: a_A held, a_B nulled, the pattern precesses.
    const double t_next = windows * kPeriodS + (kPeriodS - kWindowS);
    while (m.time_s() < t_next - 1e-9) {
      const sim::WaveState w = m.wave();
      m.set_standing_wave(1.0, w.theta_rad, 0.0, w.phase_a_rad);
      m.advance(kChunkS);
    }
    const sim::WaveState w = m.wave();
    m.set_standing_wave(1.0, w.theta_rad, 0.0, w.phase_a_rad);
    // Free-decay window.
    est.begin_window(m.time_s());
    free_decay_window(m, kWindowS, kQuadratureNoiseV, rng,
                      [&](const WaveSample& s) { est.add_sample(s); });
    off_time_s += kWindowS;
    ++windows;
    est.end_window();
    const Solution s = est.solve_and_accept();
    if (!s.accepted()) continue;
    if (first_accept_s < 0) first_accept_s = m.time_s();
    const double err = adb_error_deg_h(s.p, truth, K);
    if (err <= kGoalDegH) {
      if (converged_at_s < 0) converged_at_s = m.time_s();
    } else {
      converged_at_s = -1;
    }
    const double self_3sigma =
        3.0 * std::sqrt(0.5 * (s.covariance(kDnuC, kDnuC) + s.covariance(kDnuS, kDnuS))) / K *
        kRadSToDegH;
    if (self_3sigma <= kGoalDegH && self_converged_at_s < 0) self_converged_at_s = m.time_s();
  }

  // Parked angles: the apparent rate at Omega = 0 with a_B = 0.
  constexpr int kParked = 32;
  double th[kParked], raw[kParked], comp[kParked];
  m.set_rate_profile(sim::Profile::constant(0.0));
  for (int k = 0; k < kParked; ++k) {
    th[k] = 0.013 + k * (M_PI / 2) / kParked;
    m.set_standing_wave(1.0, th[k], 0.0, 0.0);
    const double th0 = m.wave().theta_rad;
    const double h = 1e-3;
    m.advance(h);
    const double dth = std::remainder(m.wave().theta_rad - th0, M_PI / 2);
    const double raw_rad_s = -2.0 * dth / (K * h);
    raw[k] = raw_rad_s * kRadSToDegH;
    comp[k] = (raw_rad_s + est.drift_rate_rad_s(th[k], 0.0) / K) * kRadSToDegH;
  }
  const BiasFit fr = fit_parked(th, raw);
  const BiasFit fc = fit_parked(th, comp);
  // The paper's other variants on the same normal equations.
  double comp_variant[4] = {0, 0, 0, 0};
  for (int v = 0; v < 4; ++v) {
    const Solution sv = est.normal_equations().solve(static_cast<Variant>(v));
    double cv[kParked];
    for (int k = 0; k < kParked; ++k)
      cv[k] =
          comp[k] + (resonator_drift_rad_s(sv.p, th[k], 0.0) - est.drift_rate_rad_s(th[k], 0.0)) /
                        K * kRadSToDegH;
    comp_variant[v] = sv.accepted() ? fit_parked(th, cv).amplitude() : -1.0;
  }
  const Solution& s = est.last_solution();
  const ParamMatrix crb = est.cramer_rao_bound(kQuadratureNoiseV);
  const HourResult result{fr.amplitude(), fc.amplitude(), converged_at_s, self_converged_at_s};
  if (!verbose) return result;

  std::printf(
      "\nEstimator accuracy, 1 h on the averaged model (f 5 kHz, Q 5e6, dQ/Q 0.1, "
      "split 5e-4 Hz, noise %.2e V/quadrature at 1 kHz)\n",
      kQuadratureNoiseV);
  std::printf("  windows %d x %.1f s, excitation off %.1f %% of the time\n", windows, kWindowS,
              100.0 * off_time_s / kHourS);
  std::printf("  raw ADB         b %+8.4f  A %+9.4f  B %+9.4f  |ADB| %9.4f deg/h\n", fr.b0,
              fr.a_sin4, fr.b_cos4, fr.amplitude());
  std::printf("  compensated ADB b %+8.4f  A %+9.4f  B %+9.4f  |ADB| %9.4f deg/h (goal <= %.2f)\n",
              fc.b0, fc.a_sin4, fc.b_cos4, fc.amplitude(), kGoalDegH);
  std::printf(
      "  compensated |ADB| by variant: joint %.4f, damping-only %.4f, split-only %.4f "
      "(no anisotropy model), alternating %.4f deg/h\n",
      comp_variant[0], comp_variant[1], comp_variant[2], comp_variant[3]);
  std::printf(
      "  first accepted estimate at %.0f s; converged (ADB error <= %.2f deg/h and staying) "
      "at %.0f s; estimator's own 3 sigma <= %.2f deg/h at %.0f s\n",
      first_accept_s, kGoalDegH, converged_at_s, kGoalDegH, self_converged_at_s);
  std::printf("  conditioning kappa_2 %.3f  kappa_1 %.3f  Hadamard %.3f\n", s.cond.kappa_2,
              s.cond.kappa_1, s.cond.hadamard);
  const char* names[kParams] = {"nu", "dnu_C", "dnu_S", "dw_C", "dw_S"};
  std::printf("  param   truth         estimate      error       1 sigma     sqrt(CRB)\n");
  for (int i = 0; i < kParams; ++i) {
    std::printf("  %-6s %+.6e %+.6e %+.3e %.3e %.3e\n", names[i], truth(i), s.p(i),
                s.p(i) - truth(i), std::sqrt(s.covariance(i, i)), std::sqrt(crb(i, i)));
  }
  std::printf("  residual noise sigma_hat %.3e V (injected %.3e V)\n", s.sigma_hat_v,
              kQuadratureNoiseV);
  return result;
}

int main() {
  const HourResult main_run = run_hour(2024, true);
  // The same hour with other noise seeds: the spread of the result.
  constexpr int kSeeds = 20;
  double worst = 0, sum = 0, conv_worst = 0;
  int met = 0;
  for (int i = 0; i < kSeeds; ++i) {
    const HourResult r = run_hour(100 + i, false);
    worst = std::max(worst, r.comp_adb_deg_h);
    sum += r.comp_adb_deg_h;
    met += r.comp_adb_deg_h <= kGoalDegH ? 1 : 0;
    conv_worst = std::max(conv_worst, r.converged_at_s < 0 ? kHourS : r.converged_at_s);
  }
  std::printf(
      "  over %d more noise seeds: compensated ADB mean %.4f, max %.4f deg/h; %d/%d meet "
      "%.2f deg/h; latest convergence %.0f s\n",
      kSeeds, sum / kSeeds, worst, met, kSeeds, kGoalDegH, conv_worst);
  for (double tau : {600.0, 1800.0}) {
    const HourResult r = run_hour(2024, false, tau);
    std::printf(
        "  forgetting time %.0f s (tracks temperature and ageing): compensated ADB %.4f "
        "deg/h\n",
        tau, r.comp_adb_deg_h);
  }
  return main_run.comp_adb_deg_h <= kGoalDegH ? 0 : 1;
}
