// SPDX-License-Identifier: MIT
// Cost of the estimator's steps, for callgrind (bench_cost.cmake counts the
// instructions inside each hrg_bench_est_* function and divides by its count).
//   bench_estimator_cost <op> <count>
//   op: sample | window | solve | solve_alt | output | selfcal_sample | selfcal_solve |
//       selfcal_checks | selfcal_weigh | modelcheck_sample | modelcheck_solve | pumpdrift_sample |
//       knowngap_step
#include <estimator/damping_model_check.hpp>
#include <estimator/estimator.hpp>
#include <estimator/pickoff_evidence.hpp>
#include <estimator/pickoff_self_calibration.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "synthetic_decay.hpp"

using namespace hrg::est;
using namespace hrg::est::test;

namespace {
constexpr int kWindowSamples = 3000;

std::vector<WaveSample> window_samples(double theta0, double t0) {
  const SyntheticDecay gen{seed_params(0.2, 0.5), 0.554, 0.0};
  std::mt19937_64 rng(3);
  DecayState s{t0, 1.0, 0.0, theta0};
  std::vector<WaveSample> out;
  for (int i = 0; i < kWindowSamples; ++i) {
    gen.step(s, 1e-3);
    out.push_back(gen.measure(s, 2e-5, rng));
  }
  return out;
}
}  // namespace

extern "C" {
void hrg_bench_selfcal_sample(PickoffSelfCalibration& cal, const WaveSample* s, int n);
PickoffSelfCalResult hrg_bench_selfcal_solve(const PickoffSelfCalibration& cal);
double hrg_bench_selfcal_checks(const PickoffSelfCalResult& r, const ParamVector& p);
double hrg_bench_selfcal_weigh(const PickoffSelfCalResult& r, const PickoffMap& in_force);
void hrg_bench_modelcheck_sample(DampingModelCheck& c, const WaveSample* s, int n);
DampingModelCheckResult hrg_bench_modelcheck_solve(const DampingModelCheck& c);
double hrg_bench_pumpdrift_sample(PumpDriftEstimator& f, const PumpDriftEstimator::Sample* s,
                                  int n);
double hrg_bench_knowngap_step(KnownGapDrift& g, const ParamVector& p, int n);
}

namespace {
// 16 windows while the pattern turns (the synthetic decay at rest, turned
// by hand so that the level regressors vary), then the op.
int run_self_calibration(const char* op, int count) {
  PickoffSelfCalibration cal;
  const bool sample_op = std::strcmp(op, "selfcal_sample") == 0;
  double sink = 0;
  for (int k = 0; k < 16; ++k) {
    auto samples = window_samples(0.05 + k * M_PI / 32, 10.0 * k);
    for (std::size_t i = 0; i < samples.size(); ++i)
      samples[i].theta_A_rad += (k % 3) * 0.05 * 1e-3 * static_cast<double>(i);
    const int reps = sample_op && k == 15 ? count : 1;
    for (int r = 0; r < reps; ++r) {
      cal.abort_window();
      cal.begin_window();
      if (sample_op && k == 15) {
        hrg_bench_selfcal_sample(cal, samples.data(), kWindowSamples);
      } else {
        for (const auto& s : samples)
          cal.add_sample(s);
      }
    }
    cal.end_window();
  }
  if (std::strcmp(op, "selfcal_checks") == 0) {
    // The synthetic windows do not pass the per-window decay test, and the
    // checks return at once then: count them on a solve that passes.
    PickoffSelfCalResult solved = cal.solve();
    solved.status = Status::ok;
    solved.decay_consistent = true;
    for (int r = 0; r < count; ++r)
      sink += hrg_bench_selfcal_checks(solved, seed_params(0.2, 0.5));
  } else if (std::strcmp(op, "selfcal_weigh") == 0) {
    PickoffSelfCalResult solved = cal.solve();
    solved.status = Status::ok;
    const PickoffMap in_force{0.01, 0.008, 0.017};
    for (int r = 0; r < count; ++r)
      sink += hrg_bench_selfcal_weigh(solved, in_force);
  } else if (!sample_op) {
    for (int r = 0; r < count; ++r)
      sink += hrg_bench_selfcal_solve(cal).gain;
  }
  std::printf("%s %d %.3e\n", op, count, sink);
  return 0;
}

// 16 windows at different temperatures (a damping scale of +-0.4 % on a
// cycle of 7 windows), then the op.
int run_model_check(const char* op, int count) {
  DampingModelCheck check;
  const bool sample_op = std::strcmp(op, "modelcheck_sample") == 0;
  double sink = 0;
  for (int k = 0; k < 16; ++k) {
    auto samples = window_samples(0.05 + k * M_PI / 32, 10.0 * k);
    for (auto& s : samples)
      s.damping_scale = 1.0 + 0.004 * std::sin(2.0 * M_PI * k / 7.0);
    const int reps = sample_op && k == 15 ? count : 1;
    for (int r = 0; r < reps; ++r) {
      check.abort_window();
      check.begin_window();
      if (sample_op && k == 15) {
        hrg_bench_modelcheck_sample(check, samples.data(), kWindowSamples);
      } else {
        for (const auto& s : samples)
          check.add_sample(s);
      }
    }
    check.end_window();
  }
  if (!sample_op) {
    for (int r = 0; r < count; ++r)
      sink += hrg_bench_modelcheck_solve(check).factor;
  }
  std::printf("%s %d %.3e\n", op, count, sink);
  return 0;
}

// The pump's drift fit on the control-rate rows while the excitation is on:
// a pump beside a turning pattern (segments folded every 10 s, the fit's
// figures refreshed after each fold), 1 kHz rows.
int run_pump_drift(int count) {
  PumpDriftEstimator::Config cfg;
  cfg.pump_lag_samples = 3;
  PumpDriftEstimator fit(cfg);
  fit.set_model(seed_params(0.2, 0.5));
  std::vector<PumpDriftEstimator::Sample> rows(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    auto& r = rows[static_cast<std::size_t>(i)];
    r.t_s = 1e-3 * i;
    r.theta_A_rad = 0.3 * r.t_s;
    r.a_A_v = 1.0 + 1e-4 * std::sin(0.7 * r.t_s);
    r.a_B_v = 1e-3;
    r.pump_v = 2.0 + 0.01 * std::cos(4.0 * r.theta_A_rad);
  }
  const double sink = hrg_bench_pumpdrift_sample(fit, rows.data(), count);
  std::printf("pumpdrift_sample %d %.3e\n", count, sink);
  return 0;
}

int run_known_gap(int count) {
  KnownGapDrift gap;
  const double sink = hrg_bench_knowngap_step(gap, seed_params(0.2, 0.5), count);
  std::printf("knowngap_step %d %.3e\n", count, sink);
  return 0;
}
}  // namespace

extern "C" {
// Settled samples only (the settle rule is a comparison).
__attribute__((noipa)) void hrg_bench_est_sample(WindowAccumulator& acc, const WaveSample* s,
                                                 int n) {
  for (int i = 0; i < n; ++i)
    acc.add_sample(s[i]);
}
__attribute__((noipa)) void hrg_bench_est_window(WindowAccumulator& acc, NormalEquations& ls,
                                                 WindowContribution& w) {
  if (acc.end_window(w) == Status::ok) ls.add_window(w);
}
__attribute__((noipa)) Solution hrg_bench_est_solve(const NormalEquations& ls, Variant v) {
  return ls.solve(v);
}
// The pickoff self-calibration's per-sample step (runs beside add_sample in
// every window) and its solve (after every window).
__attribute__((noipa)) void hrg_bench_selfcal_sample(PickoffSelfCalibration& cal,
                                                     const WaveSample* s, int n) {
  for (int i = 0; i < n; ++i)
    cal.add_sample(s[i]);
}
__attribute__((noipa)) PickoffSelfCalResult hrg_bench_selfcal_solve(
    const PickoffSelfCalibration& cal) {
  return cal.solve();
}
// The firmware's two readout checks on each solve: the seed model's damping
// anisotropy against the self-calibration's, and the readout pattern's
// significance (they decide whether the compensation and D_Phi stand).
__attribute__((noipa)) double hrg_bench_selfcal_checks(const PickoffSelfCalResult& r,
                                                       const ParamVector& p) {
  return damping_anisotropy_disagreement_sigmas(r, p, 1e-6, 1e-6) + readout_pattern_sigmas(r);
}
// A self-calibration round's weighing: the map to put in force (each part of
// the whole estimate weighted by its evidence) and the step to refer the
// windows through.
__attribute__((noipa)) double hrg_bench_selfcal_weigh(const PickoffSelfCalResult& r,
                                                      const PickoffMap& in_force) {
  const PickoffMap to = evidence_weighted_map(in_force, r);
  return step_between(in_force, to, r).gain;
}
// The damping model check's per-sample step (beside add_sample while a
// calibration with a damping part is in force) and its solve.
__attribute__((noipa)) void hrg_bench_modelcheck_sample(DampingModelCheck& c, const WaveSample* s,
                                                        int n) {
  for (int i = 0; i < n; ++i)
    c.add_sample(s[i]);
}
__attribute__((noipa)) DampingModelCheckResult hrg_bench_modelcheck_solve(
    const DampingModelCheck& c) {
  return c.solve();
}
// The pump's drift fit per row (segment folds and refreshes included) and
// the known gap's D_Phi per output sample.
__attribute__((noipa)) double hrg_bench_pumpdrift_sample(PumpDriftEstimator& f,
                                                         const PumpDriftEstimator::Sample* s,
                                                         int n) {
  double d = 0;
  for (int i = 0; i < n; ++i) {
    f.add_sample(s[i]);
    d += f.d_phi_rad_s(s[i].theta_A_rad);
  }
  return d;
}
__attribute__((noipa)) double hrg_bench_knowngap_step(KnownGapDrift& g, const ParamVector& p,
                                                      int n) {
  double d = 0;
  for (int i = 0; i < n; ++i) {
    const double t_s = 1e-3 * i;
    d += g.step(p, 0.02, 0.01, t_s, 0.3 * t_s, 1.0 - 1e-5 * t_s, 1e-3, 1.0);
  }
  return d;
}
__attribute__((noipa)) double hrg_bench_est_output(DriftCompensator& comp, int n) {
  double c = 0;
  for (int i = 0; i < n; ++i)
    c = comp.step(0.001 * i, 0.001, 1e-7, 1e-3);
  return c;
}
}

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr,
                 "usage: %s sample|window|solve|solve_alt|output|selfcal_sample|selfcal_solve|"
                 "selfcal_checks|selfcal_weigh|modelcheck_sample|modelcheck_solve|pumpdrift_sample|"
                 "knowngap_step "
                 "<count>\n",
                 argv[0]);
    return 2;
  }
  const char* op = argv[1];
  const int count = std::atoi(argv[2]);
  if (std::strncmp(op, "selfcal", 7) == 0) return run_self_calibration(op, count);
  if (std::strncmp(op, "modelcheck", 10) == 0) return run_model_check(op, count);
  if (std::strcmp(op, "pumpdrift_sample") == 0) return run_pump_drift(count);
  if (std::strcmp(op, "knowngap_step") == 0) return run_known_gap(count);
  // A well-covered state to solve: 16 windows.
  NormalEquations ls;
  WindowAccumulator acc;
  WindowContribution w;
  for (int k = 0; k < 16; ++k) {
    const auto samples = window_samples(0.05 + k * M_PI / 32, 10.0 * k);
    acc.begin_window(samples.front().t_s - 0.5);
    const bool last = k == 15;
    if (last && std::strcmp(op, "sample") == 0) {
      for (int r = 0; r < count; ++r) {
        acc.abort_window();
        acc.begin_window(samples.front().t_s - 0.5);
        hrg_bench_est_sample(acc, samples.data(), kWindowSamples);
      }
    } else {
      for (const auto& s : samples)
        acc.add_sample(s);
    }
    if (last && std::strcmp(op, "window") == 0) {
      hrg_bench_est_window(acc, ls, w);
    } else if (acc.end_window(w) == Status::ok) {
      ls.add_window(w);
    }
  }
  double sink = 0;
  if (std::strcmp(op, "solve") == 0 || std::strcmp(op, "solve_alt") == 0) {
    const Variant v = op[5] == '_' ? Variant::alternating : Variant::joint;
    for (int r = 0; r < count; ++r)
      sink += hrg_bench_est_solve(ls, v).p(kDnuC);
  }
  if (std::strcmp(op, "output") == 0) {
    DriftCompensator comp{0.554};
    comp.set_model(seed_params(0.2, 0.5));
    sink += hrg_bench_est_output(comp, count);
  }
  std::printf("%s %d %.3e\n", op, count, sink);
  return 0;
}
