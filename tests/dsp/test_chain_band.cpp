// SPDX-License-Identifier: MIT
// The closed loops at resonances spread over the band the decimator serves
// (2..12 kHz at 100 kHz, 100-frame blocks), off and on multiples of 500 Hz:
// PLL acquisition from +-2 Hz, AGC and quadrature nulling, the pattern
// following +-100 deg/s. Same resonator as the 5 kHz tests otherwise.
#include <cmath>
#include <cstdio>
#include <numbers>

#include "chain_rig.hpp"
#include "dsp/wave_variables.hpp"
#include "sim_target/params.hpp"

#include "support/cpputest.hpp"

using namespace hrg::dsp;
using namespace hrg::dsp::test;

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kBandHz[] = {2000.0, 3170.0, 4800.0, 5250.0, 6730.0, 8350.0, 10120.0, 12000.0};

hrg::sim::ResonatorParams resonator_at(double f_hz) {
  hrg::sim::ResonatorParams rp;
  rp.f_hz = f_hz;
  return rp;
}

ChainConfig config_at(double f_center_hz, double f_nominal_hz) {
  ChainConfig c = rig_config();
  c.f_center_hz = f_center_hz;
  c.f_min_hz = f_nominal_hz - 10.0;
  c.f_max_hz = f_nominal_hz + 10.0;
  return c;
}

// Time at which a sampled angle history first passes `level` (linear
// interpolation between blocks), or -1.
struct Crossing {
  double level;
  double dir;
  double t_s = -1.0;
  void feed(double t_prev, double th_prev, double t, double th) {
    if (t_s >= 0.0 || (th - level) * dir < 0.0) return;
    t_s = t_prev + (t - t_prev) * (level - th_prev) / (th - th_prev);
  }
};
}  // namespace

TEST_GROUP(ClosedLoopOverTheBand){};

TEST(ClosedLoopOverTheBand, PllAcquiresFromTwoHertzOffAtEveryResonance) {
  for (double f : kBandHz) {
    double worst_lock_s = 0.0;
    for (double offset_hz : {-2.0, 2.0}) {
      // GIVEN a ringing wave at f and an NCO 2 Hz away from it
      const ChainConfig cfg = config_at(f + offset_hz, f);
      CHECK(check_chain_config(cfg) == nullptr);
      ChainRig<q31_t> rig(cfg, resonator_at(f));
      rig.resonator().set_standing_wave(1.0, 17.0 * kDeg, 0.0, 0.3);
      rig.chain().set_excitation(true);
      double lock_s = -1.0;
      rig.run(2.0, [&] {
        if (lock_s < 0.0 && rig.out().locked) lock_s = rig.time_s();
      });
      // THEN lock within 2 s on the resonance (within the half split)
      CHECK(lock_s > 0.0 && lock_s < 2.0);
      DOUBLES_EQUAL(f, rig.out().pll_freq_hz, 5e-4);
      CHECK(std::fabs(rig.out().phase_err_rad) < 1e-3);
      worst_lock_s = std::fmax(worst_lock_s, lock_s);
    }
    std::printf("\n  %.0f Hz: lock from +-2 Hz in %.3f s", f, worst_lock_s);
  }
  std::printf("\n");
}

TEST(ClosedLoopOverTheBand, AgcAndQuadratureHoldAtEveryResonance) {
  for (double f : kBandHz) {
    // GIVEN the wave 1 % below the set point with quadrature, at 22.5 deg.
    // The pump's authority falls with frequency: at its limit the wave grows
    // at nu ((V_max / V_threshold)^2 sin(x)/x - 1), x = 2 pi f / fs (hold
    // loss at 2f), so the AGC is given 3 s or 1.5 times that slew, whichever
    // is longer, before the check.
    const hrg::sim::ResonatorParams rp = resonator_at(f);
    const hrg::sim::ElectrodeParams ep;
    const double x = 2.0 * kPi * f / 100000.0;
    const double v_ratio = 10.0 / ep.threshold_v(rp.omega_rad_s(), rp.nu_per_s());
    const double growth_per_s = rp.nu_per_s() * (v_ratio * v_ratio * std::sin(x) / x - 1.0);
    const double settle_s = std::fmax(3.0, 1.5 * std::log(1.0 / 0.99) / growth_per_s);
    ChainRig<q31_t> rig(config_at(f, f), rp);
    rig.resonator().set_standing_wave(0.99, 22.5 * kDeg, 0.01, 0.0);
    rig.chain().set_excitation(true);
    rig.run(settle_s);
    double worst_a = 0.0, worst_q = 0.0;
    rig.run(2.0, [&] {
      const auto& w = rig.out().wave;
      worst_a = std::fmax(worst_a, std::fabs(w.a_A_v - 1.0));
      worst_q = std::fmax(worst_q, std::fabs(w.a_B_v / w.a_A_v));
    });
    // THEN a_A within 1e-4 of the set point and |a_B| below 1e-4 a_A
    std::printf("\n  %.0f Hz (settle %.1f s): |a_A/a_set - 1| %.1e, |a_B/a_A| %.1e, V0 %.3f V", f,
                settle_s, worst_a, worst_q, rig.out().pump_v);
    CHECK(worst_a < 1e-4);
    CHECK(worst_q < 1e-4);
    CHECK(rig.out().locked);
  }
  std::printf("\n");
}

TEST(ClosedLoopOverTheBand, PatternFollowsHundredDegreesPerSecondAtEveryResonance) {
  int i = 0;
  for (double f : kBandHz) {
    // GIVEN +100 deg/s (even entries) or -100 deg/s (odd) and all loops closed
    const double omega = (i++ % 2 == 0 ? 100.0 : -100.0) * kDeg;
    const hrg::sim::ResonatorParams rp = resonator_at(f);
    ChainRig<q31_t> rig(config_at(f, f), rp);
    rig.resonator().set_rate_profile(hrg::sim::Profile::constant(omega));
    rig.resonator().set_standing_wave(1.0, 0.1);
    rig.chain().set_excitation(true);
    rig.run(1.0);
    // WHEN theta_A is followed over one period of 4 theta (pi/2 rad)
    const double expected = -rp.angular_gain * omega / 2.0;
    const double dir = expected > 0.0 ? 1.0 : -1.0;
    const double m0 = rig.out().theta_A_rad + 0.01 * dir;
    Crossing c0{m0, dir}, c1{m0 + dir * kPi / 2.0, dir};
    double prev_t = rig.time_s(), prev_m = rig.out().theta_A_rad, worst_a = 0.0;
    rig.run(4.5, [&] {
      const double t = rig.time_s(), m = rig.out().theta_A_rad;
      c0.feed(prev_t, prev_m, t, m);
      c1.feed(prev_t, prev_m, t, m);
      worst_a = std::fmax(worst_a, std::fabs(rig.out().wave.a_A_v - 1.0));
      prev_t = t;
      prev_m = m;
    });
    CHECK(c0.t_s > 0 && c1.t_s > c0.t_s);
    const double rate = (c1.level - c0.level) / (c1.t_s - c0.t_s);
    // THEN the mean rate is -K Omega / 2 within 1e-5 relative, a_A held
    std::printf("\n  %.0f Hz, %+.0f deg/s: theta_A' rel. error %.1e, |a_A - 1| %.1e", f,
                omega / kDeg, rate / expected - 1.0, worst_a);
    DOUBLES_EQUAL(expected, rate, 1e-5 * std::fabs(expected));
    CHECK(worst_a < 1e-4);
  }
  std::printf("\n");
}

TEST(ClosedLoopOverTheBand,
     PumpHoldsTheVibrationAtItsThresholdWithNoFrequencyPullAtEveryResonance) {
  for (double f : kBandHz) {
    // GIVEN an isotropic resonator at f ringing at the set point, all loops closed
    hrg::sim::ResonatorParams rp = resonator_at(f);
    rp.dmu = 0.0;
    rp.split_hz = 0.0;
    const hrg::sim::ElectrodeParams ep;
    ChainRig<q31_t> rig(config_at(f, f), rp);
    rig.resonator().set_standing_wave(1.0, 0.3, 0.0, 0.0);
    rig.chain().set_excitation(true);
    rig.run(10.0);
    // WHEN the NCO's frequency (its quantised step, what the mixer runs at)
    // and V0^2 are averaged over 20 s of steady state
    double sum_hz = 0.0, sum_v2 = 0.0;
    long n = 0;
    rig.run(20.0, [&] {
      sum_hz += hz_of_phase_step(phase_step_of_hz(rig.out().pll_freq_hz, 100000.0), 100000.0);
      sum_v2 += rig.out().pump_v * rig.out().pump_v;
      ++n;
    });
    const double w = rp.omega_rad_s();
    const double x = w / 100000.0;
    const double sinc = std::sin(x) / x;
    const double th2 = std::pow(ep.threshold_v(w, rp.nu_per_s()), 2);
    const double share = sum_v2 / static_cast<double>(n) * sinc / th2;
    const double g = ep.pump_gain_per_s2_v2 * sum_v2 / static_cast<double>(n) * sinc / (8.0 * w);
    const double pull = 2.0 * kPi * (sum_hz / static_cast<double>(n) - f) / g;
    std::printf("\n  %.0f Hz: V0^2 sinc / V_th^2 %.5f, pull %+.1e of the pump's rate", f, share,
                pull);
    // THEN the pump works at its best phase: V0^2 is the threshold raised by
    // the hold's sinc within 1e-3, and the vibration rings at the resonator's own
    // frequency within 1e-3 of the pump's rate (a phase error d pulls
    // g tan 2d; with the simulated resonator's <V^2> taken over 20 samples
    // whatever the resonance: 0.854 and a pull of 0.16 at 2 kHz, 0.954 and
    // 0.155 at 4.2 kHz, 1.090 and 0.099 at 6 kHz)
    DOUBLES_EQUAL(1.0, share, 1e-3);
    CHECK(std::fabs(pull) < 1e-3);
  }
  std::printf("\n");
}
