// SPDX-License-Identifier: MIT
// The estimator port's health: the readout checks' figures it reports every
// frame are those of the self-identification and the model in force now,
// after solves, a pickoff correction and a restart alike.
#include "firmware/estimator_port.hpp"

#include <cmath>
#include <random>

#include "dsp/wave_variables.hpp"
#include "estimator/synthetic_decay.hpp"

#include "support/cpputest.hpp"

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kK = 0.554;
constexpr double kGain = 0.01;
constexpr double kPhaseRad = 0.3 * kDeg;
constexpr double kRatesDps[] = {0.0, 100.0, -60.0, 30.0};

// One sample through a y pickoff of gain 1 + kGain and phase lag kPhaseRad,
// white noise on the quadratures.
hrg::fw::ChainRecord measure(const hrg::est::test::DecayState& s, std::mt19937_64& rng) {
  auto q = hrg::dsp::quadratures_of_wave<double>(s.a_A_v, s.a_B_v, s.theta_rad, 0.3);
  const double cy = (1.0 + kGain) * q.cy;
  const double sy = (1.0 + kGain) * q.sy;
  q.cy = std::cos(kPhaseRad) * cy - std::sin(kPhaseRad) * sy;
  q.sy = std::cos(kPhaseRad) * sy + std::sin(kPhaseRad) * cy;
  std::normal_distribution<double> n(0.0, 1e-4);
  q.cx += n(rng);
  q.sx += n(rng);
  q.cy += n(rng);
  q.sy += n(rng);
  const auto w = hrg::dsp::wave_variables<double>(q);
  hrg::fw::ChainRecord r;
  r.t_s = s.t_s;
  r.wave.a_A_v = w.a_A_v;
  r.wave.a_B_v = w.a_B_v;
  r.wave.E_v2 = w.E_v2;
  r.theta_A_rad = w.theta_A_rad;
  return r;
}

// `count` free decays of 1 s at 1 kHz from window `first` on (the seed's
// resonator; the table at kRatesDps in turn), each solved after it ends.
void feed(hrg::fw::EstimatorPort& port, int first, int count) {
  std::mt19937_64 rng(7 + static_cast<unsigned>(first));
  const auto p = hrg::est::test::seed_params(20.0 * kDeg, 5.0 * kDeg);
  for (int w = first; w < first + count; ++w) {
    const hrg::est::test::SyntheticDecay decay(p, kK, kRatesDps[w % 4] * kDeg);
    hrg::est::test::DecayState s{100.0 * w, 1.0, 1e-3, (13.0 * w) * kDeg};
    port.begin_window(s.t_s);
    for (int i = 0; i < 1000; ++i) {
      port.add_sample(measure(s, rng));
      decay.step(s, 1e-3);
    }
    port.end_window();
    port.solve();
  }
}

// The figures health() reports against those computed now from the port's
// self-identification and model.
void check_figures_are_current(const hrg::fw::EstimatorPort& port) {
  const hrg::fw::EstimatorHealth h = port.health();
  const auto& cal = port.pickoff_self_calibration();
  DOUBLES_EQUAL(hrg::est::readout_pattern_sigmas(cal), h.readout_pattern_sigmas, 0.0);
  DOUBLES_EQUAL(hrg::est::readout_phase_sigmas(cal), h.readout_phase_sigmas, 0.0);
  const double share = port.estimator().has_model()
                           ? hrg::est::readout_phase_drift_share(cal, port.estimator().model())
                           : 0.0;
  DOUBLES_EQUAL(share, h.readout_phase_drift_share, 0.0);
}

}  // namespace

TEST_GROUP(EstimatorPortHealth){};

TEST(EstimatorPortHealth, ReadoutFiguresFollowEverySolveCorrectionAndRestart) {
  hrg::fw::EstimatorPort port(hrg::est::Estimator::Config{});
  check_figures_are_current(port);
  feed(port, 0, 40);
  check_figures_are_current(port);
  // A 1 % gain and a 0.3 deg phase lag stand far from zero (sigmas ~1e-5
  // and ~1e-3 deg on 40 windows); the phase read to within a few
  // thousandths of a degree beside the gain.
  const hrg::fw::EstimatorHealth solved = port.health();
  const auto& cal = port.pickoff_self_calibration();
  CHECK_TRUE(port.estimator().has_model());
  CHECK_TRUE(solved.readout_pattern_sigmas > 100.0);
  CHECK_TRUE(solved.readout_phase_sigmas > 100.0);
  DOUBLES_EQUAL(kPhaseRad, cal.phase_rad, 0.01 * kPhaseRad);
  CHECK_TRUE(solved.readout_phase_drift_share > 0.0);

  // The self-identification's result put in force: the model forgets its
  // windows, the figures go with it until the next solve.
  const hrg::est::PickoffSelfCalResult applied = port.pickoff_self_calibration();
  port.restart_after_correction(applied);
  check_figures_are_current(port);
  DOUBLES_EQUAL(0.0, port.health().readout_pattern_sigmas, 0.0);
  DOUBLES_EQUAL(0.0, port.health().readout_phase_drift_share, 0.0);
  DOUBLES_EQUAL(0.0, port.health().readout_damping_sigmas, 0.0);

  // A model restart (the signals changed) leaves no model for the share.
  port.restart_model();
  check_figures_are_current(port);
  DOUBLES_EQUAL(0.0, port.health().readout_phase_drift_share, 0.0);
}
