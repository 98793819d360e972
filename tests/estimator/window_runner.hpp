// SPDX-License-Identifier: MIT
#pragma once

// Feeds synthetic free-decay windows to a WindowAccumulator / NormalEquations.

#include <cmath>
#include <random>

#include <estimator/normal_equations.hpp>
#include <estimator/window_accumulator.hpp>

#include "synthetic_decay.hpp"

namespace hrg::est::test {

struct WindowPlan {
  double a_A0_v = 1.0;
  double q0 = 0.0;  // a_B/a_A at the switch
  double duration_s = 3.0;
  double dt_s = 1e-3;
  double noise_v = 0.0;
};

// Runs one window starting at pattern angle theta0 (switch at t0_s) and adds it.
template <typename Rng>
Status run_window(const SyntheticDecay& gen, double t0_s, double theta0, const WindowPlan& plan,
                  WindowAccumulator& acc, NormalEquations& ls, Rng& rng) {
  DecayState s{t0_s, plan.a_A0_v, plan.q0 * plan.a_A0_v, theta0};
  acc.begin_window(t0_s);
  const int n = static_cast<int>(std::lround(plan.duration_s / plan.dt_s));
  for (int i = 0; i < n; ++i) {
    gen.step(s, plan.dt_s);
    const Status st = acc.add_sample(gen.measure(s, plan.noise_v, rng));
    if (st != Status::ok && st != Status::settling) return st;
  }
  WindowContribution w;
  const Status st = acc.end_window(w);
  if (st == Status::ok) ls.add_window(w);
  return st;
}

// `count` windows spread evenly over the 4theta circle (pattern angle step
// pi/2/count), each `plan.duration_s` long, one every `period_s`.
template <typename Rng>
void run_spread(const SyntheticDecay& gen, int count, const WindowPlan& plan,
                WindowAccumulator& acc, NormalEquations& ls, Rng& rng, double period_s = 10.0,
                double theta_offset = 0.05) {
  for (int k = 0; k < count; ++k) {
    run_window(gen, k * period_s, theta_offset + k * (M_PI / 2) / count, plan, acc, ls, rng);
  }
}

}  // namespace hrg::est::test
