// SPDX-License-Identifier: MIT
// The forgetting time derived from how fast the parameters are seen to move
// (Estimator::Config::forgetting): none while the resonator is steady (the
// model keeps converging with all its windows), a finite memory once the
// damping anisotropy drifts by many of its standard errors.
#include <cmath>
#include <numbers>
#include <random>

#include <estimator/estimator.hpp>

#include "support/cpputest.hpp"
#include "synthetic_decay.hpp"

using namespace hrg::est;
using namespace hrg::est::test;

namespace {

constexpr double kNoiseV = 3e-5;  // the default scenario's per-sample amplitude noise

// One 1 s window at pattern angle theta0 (switch at t0_s), folded and solved.
template <typename Rng>
void window(Estimator& est, const ParamVector& p, double t0_s, double theta0_rad, Rng& rng) {
  const SyntheticDecay gen(p, 0.554, 0.0);
  DecayState s{t0_s, 1.0, 0.0, theta0_rad};
  est.begin_window(t0_s);
  for (int i = 0; i < 1000; ++i) {
    gen.step(s, 1e-3);
    (void)est.add_sample(gen.measure(s, kNoiseV, rng));
  }
  (void)est.end_window();
  (void)est.solve_and_accept();
}

// `count` windows every 50 s walking the 4 theta circle, the anisotropy
// scaled by 1 + drift_per_s t (a thermal damping change, say).
double run_drifting(int count, double drift_per_s) {
  std::mt19937_64 rng(7);
  Estimator::Config cfg{};
  cfg.forgetting.adaptive = true;
  Estimator est(cfg);
  const ParamVector p0 = seed_params(0.26, 0.70);
  for (int k = 0; k < count; ++k) {
    const double t = 50.0 * k;
    ParamVector p = p0;
    p(kDnuC) *= 1.0 + drift_per_s * t;
    p(kDnuS) *= 1.0 + drift_per_s * t;
    window(est, p, t, 0.05 + k * (std::numbers::pi / 2) / 16.0, rng);
  }
  CHECK(est.has_model());
  return est.forgetting_time_s();
}

}  // namespace

TEST_GROUP(Forgetting){};

TEST(Forgetting, ASteadyResonatorKeepsEveryWindow) {
  // 200 windows (10000 s): the anisotropy terms never move by 4.5 sigma.
  DOUBLES_EQUAL(0.0, run_drifting(200, 0.0), 0.0);
}

TEST(Forgetting, ADriftingAnisotropyGetsAMemoryOfItsOwn) {
  // 10 % per 10000 s: about 40 sigma of dnu over the run (sigma ~4e-7 1/s
  // for 1 s windows, dnu ~1.6e-4 1/s).
  const double tau = run_drifting(200, 1e-5);
  CHECK(tau >= Estimator::Forgetting{}.min_s);
  CHECK(tau < 1e5);
}
