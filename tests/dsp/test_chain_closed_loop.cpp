// SPDX-License-Identifier: MIT
// The chain closing its loops on the full-rate simulated resonator
// (sim_target, default resonator: 5 kHz, Q 5e6, split 5e-4 Hz, dQ/Q 0.1).
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "chain_rig.hpp"
#include "dsp/wave_variables.hpp"
#include "sim_target/params.hpp"

#include "support/cpputest.hpp"

using namespace hrg::dsp;
using namespace hrg::dsp::test;

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

// True wave variables of the simulated resonator (its analytic envelopes).
WaveVariables<double> true_wave(hrg::sim::Resonator& r) {
  std::complex<double> x, y;
  r.envelopes(x, y);
  return wave_variables(quadratures_of_envelopes(x, y));
}
}  // namespace

TEST_GROUP(ClosedLoop){};

TEST(ClosedLoop, PllAcquiresFromTwoHertzOffInUnderTwoSecondsOverAGrid) {
  double worst_lock_s = 0.0;
  for (double offset_hz : {-2.0, -1.0, 1.0, 2.0}) {
    for (double theta : {0.0, 17.0 * kDeg, 40.0 * kDeg, -29.0 * kDeg}) {
      // GIVEN a ringing wave and an NCO that starts offset_hz away from it
      ChainConfig cfg = rig_config();
      cfg.f_center_hz = 5000.0 + offset_hz;
      ChainRig<q31_t> rig(cfg);
      rig.resonator().set_standing_wave(1.0, theta, 0.0, 0.3);
      rig.chain().set_excitation(true);
      // WHEN the loops run
      double lock_s = -1.0;
      rig.run(2.0, [&] {
        if (lock_s < 0.0 && rig.out().locked) lock_s = rig.time_s();
      });
      // THEN lock is declared before 2 s, on the resonance (within the
      // half-split 2.5e-4 Hz of 5 kHz), with a sub-mrad phase error
      CHECK(lock_s > 0.0 && lock_s < 2.0);
      DOUBLES_EQUAL(5000.0, rig.out().pll_freq_hz, 5e-4);
      CHECK(std::fabs(rig.out().phase_err_rad) < 1e-3);
      worst_lock_s = std::fmax(worst_lock_s, lock_s);
    }
  }
  std::printf("\n  PLL acquisition from +-1, +-2 Hz: worst time to lock %.3f s\n", worst_lock_s);
}

TEST(ClosedLoop, PllTracksAHalfHertzPerSecondRampWithinOneMilliradian) {
  for (double sign : {1.0, -1.0}) {
    // GIVEN a resonance that ramps at +-0.5 Hz/s (thermal frequency shift of
    // 100 ppm/degC with the temperature ramping at 1 degC/s for 4 s)
    hrg::sim::Effects fx;
    fx.thermal_frequency.enabled = true;
    fx.thermal_frequency.ppm_per_c = 100.0;
    ChainRig<q31_t> rig(rig_config(), {}, {}, fx);
    rig.resonator().set_temperature_profile(
        hrg::sim::Profile::ramps({{1.0, 25.0}, {5.0, 25.0 + 4.0 * sign}}));
    rig.resonator().set_standing_wave(1.0, 0.2);
    rig.chain().set_excitation(true);
    // WHEN the loops run through the ramp
    double worst = 0.0;
    rig.run(5.0, [&] {
      if (rig.time_s() > 1.5) worst = std::fmax(worst, std::fabs(rig.out().phase_err_rad));
    });
    // THEN the phase error stays below 1 mrad (type-2 loop: r / wn^2 = 0.55 mrad)
    const double predicted = 2 * kPi * 0.5 / std::pow(2 * kPi * 12.0, 2);
    std::printf("\n  PLL on a %+.1f Hz/s ramp: max |phase error| %.3e rad (r/wn^2 = %.3e)\n",
                0.5 * sign, worst, predicted);
    CHECK(worst < 1e-3);
    DOUBLES_EQUAL(predicted, worst, 0.3 * predicted);
    CHECK(rig.out().locked);
    DOUBLES_EQUAL(5000.0 + 2.0 * sign, rig.out().pll_freq_hz, 0.01);
    // and the amplitude loop is not disturbed by the moving frequency
    DOUBLES_EQUAL(1.0, rig.out().wave.a_A_v, 1e-4);
  }
}

TEST(ClosedLoop, AgcHoldsTheAmplitudeAndQuadratureIsNulledInSteadyState) {
  double worst_a = 0.0, worst_q = 0.0, worst_true_q = 0.0, worst_v0 = 0.0;
  const hrg::sim::ResonatorParams rp;
  const hrg::sim::ElectrodeParams ep;
  for (double theta : {0.0, 11.25 * kDeg, 22.5 * kDeg, 33.0 * kDeg, -20.0 * kDeg}) {
    // GIVEN the default resonator ringing at 0.9 V with some quadrature at theta
    ChainRig<q31_t> rig(rig_config());
    rig.resonator().set_standing_wave(0.95, theta, 0.01, 0.0);
    rig.chain().set_excitation(true);
    rig.run(3.0);
    // WHEN the loops have settled, over the next 3 s
    rig.run(3.0, [&] {
      const auto& w = rig.out().wave;
      worst_a = std::fmax(worst_a, std::fabs(w.a_A_v - 1.0));
      worst_q = std::fmax(worst_q, std::fabs(w.a_B_v / w.a_A_v));
      const auto t = true_wave(rig.resonator());
      worst_true_q = std::fmax(worst_true_q, std::fabs(t.a_B_v / t.a_A_v));
    });
    // and the pump works at its best phase: V0 is the parametric threshold
    // sqrt(8 w nu_A / k_pump) of wave A (nu_A = nu (1 + dmu cos 4theta)),
    // raised by the zero-order hold's loss at 2f, sin(x)/x with x = 2 pi f / fs
    const double nu_a = rp.nu_per_s() * (1.0 + rp.dmu * std::cos(4.0 * theta));
    const double x = 2.0 * kPi * 5000.0 / 100000.0;
    const double v0 = ep.threshold_v(rp.omega_rad_s(), nu_a) / std::sqrt(std::sin(x) / x);
    worst_v0 = std::fmax(worst_v0, std::fabs(rig.out().pump_v / v0 - 1.0));
  }
  CHECK(worst_v0 < 1e-3);
  // THEN a_A stays within 1e-4 of the set point and |a_B| below 1e-4 a_A,
  // as measured and in the resonator itself
  std::printf(
      "\n  steady state: max |a_A/a_set - 1| %.2e, max |a_B/a_A| %.2e (true %.2e), "
      "V0 vs threshold %.1e\n",
      worst_a, worst_q, worst_true_q, worst_v0);
  CHECK(worst_a < 1e-4);
  CHECK(worst_q < 1e-4);
  CHECK(worst_true_q < 1e-4);
}

TEST(ClosedLoop, PumpPhaseOfPiOverFourAddsEnergyToWaveA) {
  // The resonant part of the pump force is k V0^2 a / 4 cos(psi + 2 dphi_V
  // - pi/2 + ...): with phi_V = pi/4 + d it pumps at cos(2d) of its best, so
  // the AGC needs V0(d) = V0(0) / sqrt(cos 2d); at d = pi/2 it removes energy.
  auto settle = [](double phase_rad, double t_s, double& v0, double& a_a) {
    ChainConfig cfg = rig_config();
    cfg.pump_phase_rad = phase_rad;
    ChainRig<q31_t> rig(cfg);
    rig.resonator().set_standing_wave(1.0, 0.2);
    rig.chain().set_excitation(true);
    rig.run(t_s);
    v0 = rig.out().pump_v;
    a_a = rig.out().wave.a_A_v;
  };
  double v0_best = 0, a = 0;
  settle(kPi / 4, 4.0, v0_best, a);
  for (double d : {0.3, -0.3}) {
    double v0 = 0;
    settle(kPi / 4 + d, 4.0, v0, a);
    std::printf("\n  pump phase pi/4 %+.1f rad: V0 %.5f V, V0(0)/sqrt(cos 2d) = %.5f V\n", d, v0,
                v0_best / std::sqrt(std::cos(2 * d)));
    DOUBLES_EQUAL(v0_best / std::sqrt(std::cos(2 * d)), v0, 2e-3 * v0);
    DOUBLES_EQUAL(1.0, a, 1e-4);
  }
  // At pi/4 + pi/2 the pump damps: the AGC drives it to its limit within a
  // few tens of ms and a_A decays at up to nu_A + k V0max^2 / 8w (times the
  // hold's sin(x)/x at 2f) = 0.0032 + 0.0343 1/s instead of nu_A.
  double v0 = 0;
  settle(3 * kPi / 4, 1.0, v0, a);
  const hrg::sim::ResonatorParams rp;
  const double x = 2.0 * kPi * 5000.0 / 100000.0;
  const double nu_a = rp.nu_per_s() * (1 + rp.dmu * std::cos(0.8));
  const double g_max = 87.73 * 100.0 / (8.0 * rp.omega_rad_s()) * std::sin(x) / x;
  std::printf("  pump phase 3 pi/4: a_A after 1 s %.5f V (free decay %.5f, full anti-pump %.5f)\n",
              a, std::exp(-nu_a), std::exp(-(nu_a + g_max)));
  DOUBLES_EQUAL(10.0, v0, 1e-9);
  CHECK(a >= std::exp(-(nu_a + g_max)));
  CHECK(a <= std::exp(-(nu_a + 0.8 * g_max)));
}

TEST(ClosedLoop, PumpPhaseErrorReportsTheOffsetFromTheQuarterTurn) {
  // Locked and at the set point, the wave phase against the NCO barely moves
  // from one block to the next, so the pump phased from the previous block
  // leads by the configured phi_V - phi_A: eps = pi/2 - 2 phi_V, 0 at pi/4
  // and -2 d at pi/4 + d (seed sections 6-7).
  for (double d : {0.0, 0.1, -0.05}) {
    ChainConfig cfg = rig_config();
    cfg.pump_phase_rad = kPi / 4 + d;
    ChainRig<q31_t> rig(cfg);
    rig.resonator().set_standing_wave(1.0, 0.2);
    rig.chain().set_excitation(true);
    rig.run(4.0);
    double worst = 0.0;
    rig.run(1.0,
            [&] { worst = std::fmax(worst, std::fabs(rig.out().pump_phase_error_rad + 2.0 * d)); });
    CHECK(rig.out().pump_v > 0.0);
    CHECK(worst < 1e-3);
  }
}

TEST(ClosedLoop, LoopsHoldWithPickoffNoise) {
  // GIVEN white pickoff noise of 0.3 mV rms per sample (70 dB below the wave)
  ChainRig<q31_t> rig(rig_config());
  rig.set_pickoff_noise(3e-4, 7);
  rig.resonator().set_standing_wave(1.0, 0.25);
  rig.chain().set_excitation(true);
  rig.run(2.0);
  // WHEN the loops have settled
  double sum_a = 0.0, sum_a2 = 0.0, worst_true_q = 0.0, worst_phase = 0.0;
  bool always_locked = true;
  long n = 0;
  rig.run(4.0, [&] {
    const double a = true_wave(rig.resonator()).a_A_v;
    sum_a += a;
    sum_a2 += a * a;
    ++n;
    worst_true_q = std::fmax(worst_true_q, std::fabs(true_wave(rig.resonator()).a_B_v));
    worst_phase = std::fmax(worst_phase, std::fabs(rig.out().phase_err_rad));
    always_locked = always_locked && rig.out().locked;
  });
  // THEN the true amplitude holds within 1e-4 and the quadrature stays below
  // 1e-4 a_A: the noise in each quadrature after the sinc^5 (equivalent noise
  // bandwidth 0.44 / (L T) = 440 Hz of the 50 kHz band, times 2 for the
  // mixing) is 3e-4 sqrt(2 * 440 / 50000) = 3.9e-5 V per block, and the loops
  // follow it only within their bandwidths
  const double mean = sum_a / static_cast<double>(n);
  const double rms = std::sqrt(std::fmax(0.0, sum_a2 / static_cast<double>(n) - mean * mean));
  std::printf(
      "\n  0.3 mV rms pickoff noise: a_A %.7f V (rms %.1e), max |a_B| %.1e V, max |phase| %.1e\n",
      mean, rms, worst_true_q, worst_phase);
  DOUBLES_EQUAL(1.0, mean, 1e-4);
  CHECK(rms < 1e-4);
  CHECK(worst_true_q < 1e-4);
  CHECK(always_locked);
}

TEST(ClosedLoop, LoopsRecoverWithinOneSecondAfterATwoSecondFreeDecayWindow) {
  double worst_settle_s = 0.0, worst_overshoot = 0.0, worst_decay = 0.0, worst_growth = 0.0;
  for (int run = 0; run < 8; ++run) {
    // GIVEN settled loops, over a grid of pattern angles and NCO start offsets
    const double theta = std::array<double, 4>{22.5, -22.5, 5.0, 40.0}[run % 4] * kDeg;
    ChainConfig cfg = rig_config();
    cfg.f_center_hz = 5000.0 + (run < 4 ? -2.0 : 2.0);
    ChainRig<q31_t> rig(cfg);
    rig.resonator().set_standing_wave(1.0, theta);
    rig.chain().set_excitation(true);
    rig.run(3.0);
    // WHEN excitation is off for 2 s, a_A decays and a_B grows freely
    rig.chain().set_excitation(false);
    rig.run(2.0);
    const auto& w = rig.out().wave;
    worst_decay = std::fmax(worst_decay, 1.0 - w.a_A_v);
    worst_growth = std::fmax(worst_growth, std::fabs(w.a_B_v / w.a_A_v));
    // THEN, with excitation back on, the loops settle within 1 s
    rig.chain().set_excitation(true);
    const double t_on = rig.time_s();
    double last_bad_s = 0.0, overshoot = 0.0;
    rig.run(1.5, [&] {
      const auto& o = rig.out().wave;
      overshoot = std::fmax(overshoot, o.a_A_v - 1.0);
      if (std::fabs(o.a_A_v - 1.0) > 1e-4 || std::fabs(o.a_B_v / o.a_A_v) > 1e-4)
        last_bad_s = rig.time_s() - t_on;
    });
    CHECK(last_bad_s < 1.0);
    CHECK(overshoot < 1e-3);
    worst_settle_s = std::fmax(worst_settle_s, last_bad_s);
    worst_overshoot = std::fmax(worst_overshoot, overshoot);
  }
  // The window really disturbed the wave: a_A fell by about 2 nu = 6.3e-3 and
  // a_B grew to about 2 dw a_A = 3.1e-3 a_A where sin 4(theta - th_w) = 1.
  std::printf(
      "\n  free decay 2 s: a_A fell %.2e, a_B/a_A grew to %.2e; recovery %.3f s, overshoot "
      "%.2e a_set\n",
      worst_decay, worst_growth, worst_settle_s, worst_overshoot);
  CHECK(worst_decay > 5e-3);
  CHECK(worst_growth > 2e-3);
}

TEST(ClosedLoop, RingsUpFromRestAndHandsOverToThePump) {
  for (int run = 0; run < 4; ++run) {
    const double a_set = run < 3 ? 0.05 : 1.0;
    const double offset_hz = std::array<double, 4>{0.0, 2.0, -8.0, 0.0}[run];
    // GIVEN the resonator at rest. The 5 V forcer drive raises a_A by
    // g u / 2w = 0.0159 V/s and the pump at its 10 V limit adds the growth
    // rate k 10^2 / 8w - nu = 0.0318 1/s once there is a wave:
    // a(t) = (0.0159 / 0.0318)(e^{0.0318 t} - 1) reaches 0.9 a_set at
    // t = ln(1 + 0.9 a_set / 0.5) / 0.0318 (2.7 s for 0.05 V, 32 s for 1 V).
    // The NCO may start off the resonance: the drive follows the measured wave
    // phase as soon as there is a wave, which pulls it onto the resonance.
    ChainConfig cfg = rig_config();
    cfg.amplitude_setpoint_v = a_set;
    cfg.ring_up_theta_rad = 10.0 * kDeg;
    cfg.f_center_hz = 5000.0 + offset_hz;
    ChainRig<q31_t> rig(cfg);
    rig.chain().set_excitation(true);
    // WHEN the chain runs
    double handover_s = -1.0;
    rig.run(a_set < 0.5 ? 12.0 : 45.0, [&] {
      if (handover_s < 0.0 && !rig.out().ring_up) handover_s = rig.time_s();
    });
    // THEN the handover to the pump comes when predicted and the pump holds
    // the wave at the set point along the commanded angle
    const double predicted_s = std::log(1.0 + 0.9 * a_set / 0.5) / 0.0318;
    std::printf(
        "\n  ring-up from rest, NCO %+.0f Hz off, to 0.9 x %.2f V: %.2f s (predicted %.2f s); "
        "a_A %.6f V\n",
        offset_hz, a_set, handover_s, predicted_s, rig.out().wave.a_A_v);
    DOUBLES_EQUAL(predicted_s, handover_s, 0.05 * predicted_s);
    DOUBLES_EQUAL(a_set, rig.out().wave.a_A_v, a_set * 1e-4);
    // (once rung up the pattern is free: the damping drift nu dmu sin4theta / 2
    // moves it by up to 7.9e-5 rad/s, 3.5e-3 rad over 45 s)
    const double t_run = a_set < 0.5 ? 12.0 : 45.0;
    DOUBLES_EQUAL(10.0 * kDeg, rig.out().theta_A_rad, 7.9e-5 * t_run);
    DOUBLES_EQUAL(true_wave(rig.resonator()).theta_A_rad, rig.out().wave.theta_A_rad, 1e-5);
    CHECK(rig.out().locked);
  }
}

namespace {
// Time at which a sampled angle history first passes `level` (linear
// interpolation between blocks), or -1.
struct Crossing {
  double level;
  double dir;  // -1: falling through level, +1: rising
  double t_s = -1.0;
  void feed(double t_prev, double th_prev, double t, double th) {
    if (t_s >= 0.0 || (th - level) * dir < 0.0) return;
    t_s = t_prev + (t - t_prev) * (level - th_prev) / (th - th_prev);
  }
};
}  // namespace

TEST(ClosedLoop, PatternFollowsTheInputRateWithAllLoopsClosed) {
  double worst_rel = 0.0, worst_true_rel = 0.0, worst_a = 0.0, worst_q = 0.0;
  for (double rate_dps : {100.0, -100.0}) {
    for (double theta0 : {0.1, 0.5}) {
      // GIVEN +-100 deg/s about the sensitive axis and all loops closed
      const double omega = rate_dps * kDeg;
      const hrg::sim::ResonatorParams rp;
      ChainRig<q31_t> rig(rig_config(), rp);
      rig.resonator().set_rate_profile(hrg::sim::Profile::constant(omega));
      rig.resonator().set_standing_wave(1.0, theta0);
      rig.chain().set_excitation(true);
      ThetaUnwrapper<double> true_theta;
      rig.run(1.0, [&] { true_theta.update(true_wave(rig.resonator()).theta_A_rad); });
      // WHEN theta_A (measured, and the resonator's own) is followed over
      // exactly 3 periods of 4 theta (3 pi/2 rad of pattern angle)
      const double expected = -rp.angular_gain * omega / 2.0;
      const double dir = expected > 0.0 ? 1.0 : -1.0;
      const double m0 = rig.out().theta_A_rad + 0.01 * dir;
      const double r0 = true_theta.value() + 0.01 * dir;
      Crossing cm0{m0, dir}, cm1{m0 + dir * 3.0 * kPi / 2.0, dir};
      Crossing cr0{r0, dir}, cr1{r0 + dir * 3.0 * kPi / 2.0, dir};
      double prev_t = rig.time_s(), prev_m = rig.out().theta_A_rad, prev_r = true_theta.value();
      rig.run(11.0, [&] {
        const double t = rig.time_s(), m = rig.out().theta_A_rad;
        const double r = true_theta.update(true_wave(rig.resonator()).theta_A_rad);
        cm0.feed(prev_t, prev_m, t, m);
        cm1.feed(prev_t, prev_m, t, m);
        cr0.feed(prev_t, prev_r, t, r);
        cr1.feed(prev_t, prev_r, t, r);
        worst_a = std::fmax(worst_a, std::fabs(rig.out().wave.a_A_v - 1.0));
        worst_q = std::fmax(worst_q, std::fabs(rig.out().wave.a_B_v));
        prev_t = t;
        prev_m = m;
        prev_r = r;
      });
      CHECK(cm0.t_s > 0 && cm1.t_s > cm0.t_s && cr0.t_s > 0 && cr1.t_s > cr0.t_s);
      const double rate = (cm1.level - cm0.level) / (cm1.t_s - cm0.t_s);
      const double true_rate = (cr1.level - cr0.level) / (cr1.t_s - cr0.t_s);
      // THEN the mean rate is -K Omega / 2 within 1e-5 relative
      DOUBLES_EQUAL(expected, rate, 1e-5 * std::fabs(expected));
      DOUBLES_EQUAL(expected, true_rate, 1e-5 * std::fabs(expected));
      worst_rel = std::fmax(worst_rel, std::fabs(rate / expected - 1.0));
      worst_true_rel = std::fmax(worst_true_rel, std::fabs(true_rate / expected - 1.0));
    }
  }
  std::printf(
      "\n  +-100 deg/s: theta_A' vs -K Omega/2: rel. error %.1e measured, %.1e true; "
      "|a_A - 1| %.1e, |a_B| %.1e V\n",
      worst_rel, worst_true_rel, worst_a, worst_q);
  // and the loops hold while the pattern turns
  CHECK(worst_a < 1e-4);
  CHECK(worst_q < 1e-4);
}

TEST(ClosedLoop, FloatAndFixedChainsAgreeOnThetaWithinOneMicroradianRms) {
  // GIVEN 60 s of the default resonator under the fixed-point chain's loops,
  // turning at 10 deg/s so theta_A covers 4theta twice
  ChainRig<q31_t> rig(rig_config());
  rig.resonator().set_rate_profile(hrg::sim::Profile::constant(10.0 * kDeg));
  rig.resonator().set_standing_wave(1.0, 0.3);
  rig.chain().set_excitation(true);
  // WHEN a float chain and a double chain see the same ADC blocks
  Chain<float> chain_f(rig_config());
  Chain<double> chain_d(rig_config());
  std::vector<q31_t> dac(300);
  double sum_sq = 0.0, sum_sq_d = 0.0;
  long n = 0;
  rig.run(60.0, [&] {
    chain_f.process(rig.last_adc(), dac);
    chain_d.process(rig.last_adc(), dac);
    if (rig.time_s() < 0.1) return;
    const double d = chain_f.outputs().theta_A_rad - rig.out().theta_A_rad;
    const double dd = chain_d.outputs().theta_A_rad - rig.out().theta_A_rad;
    sum_sq += d * d;
    sum_sq_d += dd * dd;
    ++n;
  });
  const double rms = std::sqrt(sum_sq / static_cast<double>(n));
  const double rms_d = std::sqrt(sum_sq_d / static_cast<double>(n));
  std::printf("\n  theta_A over 60 s: float - fixed %.2e rad rms, double - fixed %.2e rad rms\n",
              rms, rms_d);
  // THEN they agree within 1e-6 rad rms
  CHECK(rms < 1e-6);
  CHECK(rms_d < 1e-6);
  CHECK(std::fabs(rig.out().theta_A_rad - 0.3) > 2.0);  // the pattern really turned
}

TEST(ClosedLoop, PatternCommandTurnsThePatternOnPurposeAndHoldsIt) {
  // The forcers are weak against the wave: theta' = g u_r / (4 w a_A) is
  // 0.0080 rad/s = 0.456 deg/s at the 5 V limit (g = 200 1/s^2, a_A = 1 V).
  const double rate_limit = 200.0 * 5.0 / (4.0 * 2.0 * kPi * 5000.0 * 1.0);
  for (double target_deg : {7.0, 3.0}) {
    // GIVEN settled loops at theta = 5 deg
    ChainRig<q31_t> rig(rig_config());
    rig.resonator().set_standing_wave(1.0, 5.0 * kDeg);
    rig.chain().set_excitation(true);
    rig.run(0.5);
    // WHEN the pattern is commanded 2 deg away at up to 0.3 deg/s
    const double target = target_deg * kDeg;
    const double max_rate = 0.3 * kDeg;
    rig.chain().set_pattern_command(true, target, max_rate);
    const double th_start = rig.out().theta_A_rad;
    double worst_a = 0.0, worst_q = 0.0, mid_rate = 0.0;
    rig.run(10.0, [&] {
      worst_a = std::fmax(worst_a, std::fabs(rig.out().wave.a_A_v - 1.0));
      worst_q = std::fmax(worst_q, std::fabs(rig.out().wave.a_B_v));
      if (std::fabs(rig.time_s() - 3.5) < 0.5e-3)
        mid_rate = (rig.out().theta_A_rad - th_start) / (rig.time_s() - 0.5);
    });
    // THEN the pattern turned at the commanded rate, in the commanded
    // direction, and sits at the target (as measured and in the resonator),
    // with amplitude and quadrature held
    const auto t = true_wave(rig.resonator());
    const double true_err = std::remainder(t.theta_A_rad - target, kPi / 2);
    std::printf(
        "\n  pattern command 5 -> %.0f deg: rate %.4f deg/s (commanded %.1f, forcer limit %.3f), "
        "error %.1e rad (true %.1e)\n",
        target_deg, mid_rate / kDeg, 0.3, rate_limit / kDeg, rig.out().theta_A_rad - target,
        true_err);
    DOUBLES_EQUAL(std::copysign(max_rate, target - th_start), mid_rate, 0.02 * max_rate);
    // (a proportional angle loop leaves drift / gain: the damping drift
    // nu dmu sin 4theta / 2 <= 7.9e-5 rad/s over 5 1/s is <= 1.6e-5 rad)
    DOUBLES_EQUAL(target, rig.out().theta_A_rad, 2e-5);
    CHECK(std::fabs(true_err) < 2e-5);
    CHECK(worst_a < 1e-4);
    CHECK(worst_q < 1e-4);
    // and without the command no rotating force is applied
    rig.chain().set_pattern_command(false, 0.0, 0.0);
    rig.run(0.01);
    DOUBLES_EQUAL(0.0, rig.out().pattern_effort_v, 0.0);
  }
}

TEST(ClosedLoop, FloatChainClosesTheSameLoops) {
  // GIVEN the float chain on the default resonator with 0.5 Hz offset and a
  // free-decay window
  ChainConfig cfg = rig_config();
  cfg.f_center_hz = 5000.5;
  ChainRig<float> rig(cfg);
  rig.resonator().set_standing_wave(1.0, 0.4);
  rig.chain().set_excitation(true);
  rig.run(3.0);
  rig.chain().set_excitation(false);
  rig.run(2.0);
  rig.chain().set_excitation(true);
  rig.run(1.0);
  // THEN it holds the same figures as the fixed-point chain
  double worst_a = 0.0, worst_q = 0.0;
  rig.run(2.0, [&] {
    worst_a = std::fmax(worst_a, std::fabs(rig.out().wave.a_A_v - 1.0));
    worst_q = std::fmax(worst_q, std::fabs(rig.out().wave.a_B_v));
  });
  std::printf("\n  float chain: |a_A - 1| %.1e, |a_B| %.1e after a window\n", worst_a, worst_q);
  CHECK(rig.out().locked);
  CHECK(worst_a < 1e-4);
  CHECK(worst_q < 1e-4);
}
