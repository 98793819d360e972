// SPDX-License-Identifier: MIT
// Chain without a resonator: interface contracts (sizes, configuration
// errors, drives exactly zero when excitation is off, loop elements).
#include "dsp/chain.hpp"

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <vector>

#include "support/cpputest.hpp"

using namespace hrg::dsp;

namespace {
std::vector<q31_t> tone_block(uint32_t frames, double f_hz, double a, double t0_s) {
  std::vector<q31_t> v(2 * frames);
  for (uint32_t n = 0; n < frames; ++n) {
    const double t = t0_s + n / 100000.0;
    v[2 * n] = q31_from_f64_sat(a * std::cos(2 * std::numbers::pi * f_hz * t));
    v[2 * n + 1] = 0;
  }
  return v;
}
}  // namespace

TEST_GROUP(ChainConfig){};

TEST(ChainConfig, DefaultsAreUsableAndBadFieldsAreNamed) {
  CHECK(check_chain_config(ChainConfig{}) == nullptr);
  ChainConfig c;
  c.block_frames = 1;
  STRCMP_CONTAINS("block_frames", check_chain_config(c));
  c = ChainConfig{};
  c.f_max_hz = 4000.0;
  STRCMP_CONTAINS("f_max_hz", check_chain_config(c));
  c = ChainConfig{};
  c.pump_max_v = 20.0;
  STRCMP_CONTAINS("pump_max_v", check_chain_config(c));
  c = ChainConfig{};
  c.ring_up_exit = 0.05;
  STRCMP_CONTAINS("ring_up", check_chain_config(c));
  // resonances off any multiple of 500 Hz (refused before the sinc^5
  // decimator) are served now
  for (double f : {4800.0, 5250.0, 2000.0, 12000.0}) {
    c = ChainConfig{};
    c.f_min_hz = f - 10.0;
    c.f_center_hz = f;
    c.f_max_hz = f + 10.0;
    CHECK(check_chain_config(c) == nullptr);
  }
  // below the band (1594..48406 Hz at 100 kHz, 100-frame blocks): the message
  // names the frequency, the band and the block length that serves it
  c.f_min_hz = 1190.0;
  c.f_center_hz = 1200.0;
  c.f_max_hz = 1210.0;
  STRCMP_EQUAL(
      "chain config: f_min_hz 1190 Hz is outside the resonance band 1594..48406 Hz that "
      "sample_rate_hz 100000 with block_frames 100 serves (2f image >= 100 dB down); "
      "raise block_frames to at least 134 (control rate 746 Hz)",
      check_chain_config(c));
  c.block_frames = 134;
  CHECK(check_chain_config(c) == nullptr);
  // above it: the sample rate is too low
  c = ChainConfig{};
  c.sample_rate_hz = 20000.0;
  c.block_frames = 20;
  c.f_min_hz = 9990.0;
  c.f_center_hz = 10000.0;
  c.f_max_hz = 10010.0;
  STRCMP_CONTAINS("f_max_hz 10010 Hz is outside the resonance band", check_chain_config(c));
  STRCMP_CONTAINS("sample rate too low: raise sample_rate_hz to at least 24025",
                  check_chain_config(c));
  c.sample_rate_hz = 24025.0;
  CHECK(check_chain_config(c) == nullptr);
  // a block too short for 100 dB anywhere (L^5 sin^5 <= 1e5 needs L > 10)
  c = ChainConfig{};
  c.block_frames = 10;
  STRCMP_CONTAINS("too short for any resonance: raise block_frames to at least 11",
                  check_chain_config(c));
}

TEST(ChainConfig, AnUnusableConfigurationMakesProcessRefuse) {
  ChainConfig c;
  c.adc_full_scale_v = -1.0;
  Chain<q31_t> chain(c);
  std::vector<q31_t> adc(200, 0), dac(300, 7);
  CHECK_FALSE(chain.process(adc, dac));
  CHECK_EQUAL(7, dac[0]);
}

TEST_GROUP(Chain){};

TEST(Chain, RefusesAnAmplitudeSetPointOutsideTheAdcRange) {
  Chain<q31_t> chain(ChainConfig{});
  CHECK(chain.set_amplitude_setpoint_v(0.5));
  CHECK_FALSE(chain.set_amplitude_setpoint_v(0.0));
  CHECK_FALSE(chain.set_amplitude_setpoint_v(-1.0));
  CHECK_FALSE(chain.set_amplitude_setpoint_v(2.0));  // the default ADC full scale
  CHECK_FALSE(chain.set_amplitude_setpoint_v(std::nan("")));
}

TEST(Chain, RefusesBlocksOfTheWrongSize) {
  Chain<q31_t> chain(ChainConfig{});
  std::vector<q31_t> adc(200, 0), dac(300, 0), short_adc(198, 0), short_dac(297, 0);
  CHECK_FALSE(chain.process(short_adc, dac));
  CHECK_FALSE(chain.process(adc, short_dac));
  CHECK_EQUAL(0u, chain.outputs().blocks);
  CHECK(chain.process(adc, dac));
  CHECK_EQUAL(1u, chain.outputs().blocks);
}

TEST(Chain, DrivesAreExactlyZeroWhileExcitationIsOff) {
  // GIVEN a strong resonance signal and a chain whose loops would drive hard
  Chain<q31_t> chain(ChainConfig{});
  Chain<float> chain_f(ChainConfig{});
  std::vector<q31_t> dac(300, 12345), dac_f(300, 12345);
  for (int b = 0; b < 50; ++b) {
    const auto adc = tone_block(100, 5000.0, 0.3, b * 1e-3);
    chain.process(adc, dac);
    chain_f.process(adc, dac_f);
    // THEN every DAC word is 0 while excitation is off
    for (std::size_t k = 0; k < dac.size(); ++k) {
      CHECK_EQUAL(0, dac[k]);
      CHECK_EQUAL(0, dac_f[k]);
    }
  }
  // and the measurement still runs (the wave is seen, the PLL tracks it)
  DOUBLES_EQUAL(0.3 * 2.0, chain.outputs().wave.a_A_v, 1e-4);
  // WHEN excitation is switched on the pump comes on
  chain.set_excitation(true);
  chain.process(tone_block(100, 5000.0, 0.3, 0.05), dac);
  bool any = false;
  for (q31_t v : dac)
    any = any || v != 0;
  CHECK(any);
  // and off again: zero from the very next block
  chain.set_excitation(false);
  chain.process(tone_block(100, 5000.0, 0.3, 0.051), dac);
  for (q31_t v : dac)
    CHECK_EQUAL(0, v);
}

TEST(Chain, EachDriveIsExactlyZeroWhileItsEnableIsOff) {
  Chain<q31_t> chain(ChainConfig{});
  std::vector<q31_t> dac(300, 1);
  // GIVEN a wave below the ring-up threshold: pump and forcers both want to drive
  const auto adc = tone_block(100, 5000.0, 0.02, 0.0);
  // WHEN only the pump is enabled THEN the forcer channels are exactly zero
  chain.set_drive_enables(true, false);
  chain.process(adc, dac);
  bool pump_any = false;
  for (int j = 0; j < 100; ++j) {
    pump_any = pump_any || dac[3 * j] != 0;
    CHECK_EQUAL(0, dac[3 * j + 1]);
    CHECK_EQUAL(0, dac[3 * j + 2]);
  }
  CHECK(pump_any);
  // WHEN only the forcers are enabled THEN the pump channel is exactly zero
  chain.set_drive_enables(false, true);
  chain.process(adc, dac);
  bool forcer_any = false;
  for (int j = 0; j < 100; ++j) {
    CHECK_EQUAL(0, dac[3 * j]);
    forcer_any = forcer_any || dac[3 * j + 1] != 0;
  }
  CHECK(forcer_any);
  CHECK(chain.excitation());
}

TEST(Chain, FixedDriveSynthesisMatchesTheDoubleChainWithin1024Lsb) {
  // GIVEN the same ADC blocks into the Q1.31 and the double chain, in ring-up
  // (forcers at their limit, pump at its limit: the largest DAC words)
  Chain<q31_t> cq(ChainConfig{});
  Chain<double> cd(ChainConfig{});
  cq.set_excitation(true);
  cd.set_excitation(true);
  std::vector<q31_t> dq(300), dd(300);
  long worst = 0;
  for (int b = 0; b < 20; ++b) {
    const auto adc = tone_block(100, 5000.3, 0.02, b * 1e-3);
    cq.process(adc, dq);
    cd.process(adc, dd);
    // THEN every DAC word agrees within 1024 LSB of Q1.31 (4.8e-7 of full
    // scale). Synthesis itself adds ~2 LSB (table and product rounding); the
    // rest is the drive phase. The two chains' wave phases differ by up to
    // 1.5e-7 rad: LSB-level differences of the quadratures of this 0.02 FS
    // wave (1 LSB = 2.3e-8 rad), largest while the decimator fills, which the
    // PLL integrates into the NCO phase. Times the pump word at full scale
    // (2^31 LSB per rad) that is a few hundred LSB (measured 778).
    // (once the decimator is full: before, the wave is a small fraction of it)
    for (std::size_t k = 0; k < dq.size() && b >= static_cast<int>(kDecimatorOrder); ++k)
      worst = std::max(worst, std::labs(static_cast<long>(dq[k]) - static_cast<long>(dd[k])));
  }
  std::printf("\n  drive synthesis, fixed vs double: worst %ld LSB\n", worst);
  CHECK(worst <= 1024);
}

TEST(Chain, RingsUpAlongTheCommandedAngleFromRest) {
  // GIVEN silence and excitation on
  ChainConfig c;
  c.ring_up_theta_rad = std::numbers::pi / 8;  // 22.5 deg: forcers x and y equal
  Chain<double> chain(c);
  chain.set_excitation(true);
  std::vector<q31_t> adc(200, 0), dac(300, 0);
  chain.process(adc, dac);
  // THEN the pump is off (nothing to pump) and the forcers drive along the
  // pattern with amplitude forcer_max at the NCO frequency
  CHECK(chain.outputs().ring_up);
  double px = 0, fx = 0, fy = 0;
  for (int j = 0; j < 100; ++j) {
    // rms over the block's 5 whole periods
    px += std::pow(f64_from_q31(dac[3 * j]), 2) / 100.0;
    fx += std::pow(f64_from_q31(dac[3 * j + 1]), 2) / 100.0;
    fy += std::pow(f64_from_q31(dac[3 * j + 2]), 2) / 100.0;
  }
  fx = std::sqrt(2.0 * fx);
  fy = std::sqrt(2.0 * fy);
  DOUBLES_EQUAL(0.0, px, 0.0);
  const double expect = c.forcer_max_v / c.dac_full_scale_v * std::cos(std::numbers::pi / 4);
  DOUBLES_EQUAL(expect, fx, 1e-5);
  DOUBLES_EQUAL(expect, fy, 1e-5);
}

TEST_GROUP(Loops){};

TEST(Loops, PiIntegratorDoesNotWindUpAgainstALimit) {
  PiController pi;
  pi.configure(1.0, 100.0, -1.0, 1.0);
  for (int k = 0; k < 1000; ++k)
    pi.update(10.0, 1e-3);  // pushes hard into +1
  DOUBLES_EQUAL(1.0, pi.output(), 0.0);
  CHECK(pi.integrator() <= 1.0);
  // the first small negative error brings the output off the limit at once
  pi.update(-0.5, 1e-3);
  CHECK(pi.output() < 1.0);
}

TEST(Loops, LockDetectorHasHysteresis) {
  LockDetector d;
  d.configure(0.01, 0.05, 10, 1.0);  // no smoothing: level = |error|
  d.reset();
  for (int k = 0; k < 9; ++k)
    CHECK_FALSE(d.update(0.005, true));
  CHECK(d.update(0.005, true));  // 10th block below enter
  CHECK(d.update(0.03, true));   // between enter and exit: stays locked
  CHECK_FALSE(d.update(0.06, true));
  CHECK_FALSE(d.update(0.03, true));  // between: stays unlocked
  CHECK_FALSE(d.update(0.0, false));
}

TEST(Loops, PllRampErrorIsRampOverNaturalFrequencySquared) {
  // Type-2 loop against the plant phi' = w_res - w_nco, resonance ramping at
  // 0.5 Hz/s: steady phase error r / wn^2.
  Pll pll;
  Pll::Config c;
  c.natural_hz = 12.0;
  pll.configure(c);
  const double dt = 1e-3, r = 2 * std::numbers::pi * 0.5;
  double phi = 0.0, w_res = 2 * std::numbers::pi * 5000.0;
  for (int k = 0; k < 4000; ++k) {
    const double f = pll.update(phi, true, dt);
    w_res += r * dt;
    phi += (w_res - 2 * std::numbers::pi * f) * dt;
  }
  const double wn = 2 * std::numbers::pi * 12.0;
  DOUBLES_EQUAL(r / (wn * wn), phi, 0.05 * r / (wn * wn));
}

TEST(Loops, PllStaysWithinItsFrequencyLimits) {
  Pll pll;
  pll.configure(Pll::Config{5000.0, 4999.0, 5001.0, 12.0, 0.9});
  for (int k = 0; k < 5000; ++k)
    pll.update(1.0, true, 1e-3);
  DOUBLES_EQUAL(5001.0, pll.frequency_hz(), 1e-9);
  CHECK(pll.at_limit());
  pll.update(-1.0, true, 1e-3);  // no wind-up: leaves the limit at once
  CHECK(pll.frequency_hz() < 5001.0);
}

TEST_GROUP(ChainDriftInputs){};

TEST(ChainDriftInputs, PumpPhaseErrorIsZeroAtTheQuarterTurnAndWrapsIntoPlusMinusPi) {
  const double pi = std::numbers::pi;
  // eps = pi/2 - 2 (phi_V - phi_A): 0 when the pump leads by pi/4 (a quarter
  // turn of 2 phi), -2 d when it leads by pi/4 + d.
  for (double phi : {-3.0, -0.5, 0.0, 1.2, 3.1}) {
    DOUBLES_EQUAL(0.0, pump_phase_error_rad(phi + pi / 4.0, phi), 1e-12);
    DOUBLES_EQUAL(-0.2, pump_phase_error_rad(phi + pi / 4.0 + 0.1, phi), 1e-12);
  }
  // At the rails: every offset lands in (-pi, pi] and equals eps mod 2 pi.
  for (double d = -7.0; d <= 7.0; d += 0.25) {
    const double eps = pump_phase_error_rad(d, 0.0);
    CHECK(eps > -pi - 1e-12 && eps <= pi + 1e-12);
    DOUBLES_EQUAL(0.0, std::remainder(eps - (pi / 2.0 - 2.0 * d), 2.0 * pi), 1e-9);
  }
  DOUBLES_EQUAL(pi, pump_phase_error_rad(3.0 * pi / 4.0, 0.0), 1e-12);
}

TEST(ChainDriftInputs, QuadratureForceRateIsGainTimesDriveOverTwoOmega) {
  // a_B' = g u_q / (2 w): 200 /s^2/V x 1 V / (2 x 2 pi 5 kHz) = 3.183e-3 V/s.
  const double w = 2.0 * std::numbers::pi * 5000.0;
  DOUBLES_EQUAL(3.1830988618e-3, quad_force_rate_v_s(200.0, w, 1.0), 1e-13);
  DOUBLES_EQUAL(-2.0 * 3.1830988618e-3, quad_force_rate_v_s(200.0, w, -2.0), 1e-13);
  DOUBLES_EQUAL(0.0, quad_force_rate_v_s(200.0, w, 0.0), 0.0);
}

TEST(ChainDriftInputs, FirstBlockAndPumpOffReportNoPhaseErrorAndEffortIsAFraction) {
  Chain<q31_t> chain{ChainConfig{}};
  chain.set_excitation(true);
  std::vector<q31_t> dac(3 * 100);
  chain.process(tone_block(100, 5000.0, 0.4, 0.0), dac);
  DOUBLES_EQUAL(0.0, chain.outputs().pump_phase_error_rad, 0.0);
  const auto& o = chain.outputs();
  DOUBLES_EQUAL(o.quad_effort_v / ChainConfig{}.forcer_max_v, o.quad_effort, 1e-15);
  DOUBLES_EQUAL(quad_force_rate_v_s(ChainConfig{}.forcer_gain_per_s2,
                                    2.0 * std::numbers::pi * o.pll_freq_hz, o.quad_effort_v),
                o.quad_force_sin_v_s, 1e-15);
  DOUBLES_EQUAL(0.0, o.quad_force_cos_v_s, 0.0);
  chain.set_excitation(false);
  chain.process(tone_block(100, 5000.0, 0.4, 1e-3), dac);
  DOUBLES_EQUAL(0.0, chain.outputs().pump_phase_error_rad, 0.0);
}

// The pump a block's quadratures saw: the decimator's weights over the pump
// envelopes that acted in its window (each written after the block before),
// which a drive feedthrough in them is proportional to. Steady: the pump
// itself; kDecimatorOrder blocks after a switch-off: none.
TEST(Chain, PumpSeenIsTheDecimatorWeightedPumpThatActed) {
  ChainConfig cfg;
  Chain<double> chain(cfg);
  std::vector<q31_t> dac(300, 0);
  PumpEnvelopeFilter filter(cfg.block_frames);
  double written_re_v = 0.0;
  double written_im_v = 0.0;
  double t_s = 0.0;
  // A wave below the ring-up threshold: the pump runs at its limit while on.
  auto step = [&](bool pump_on) {
    chain.set_drive_enables(pump_on, false);
    chain.process(tone_block(cfg.block_frames, 5000.0, 0.02, t_s), dac);
    t_s += cfg.block_frames / cfg.sample_rate_hz;
    double re = 0.0;
    double im = 0.0;
    filter.push(written_re_v, written_im_v, re, im);
    DOUBLES_EQUAL(std::hypot(re, im), chain.outputs().pump_seen_v, 1e-12);
    written_re_v = chain.outputs().pump_v * std::cos(chain.outputs().pump_phase_rad);
    written_im_v = chain.outputs().pump_v * std::sin(chain.outputs().pump_phase_rad);
  };
  for (int n = 0; n < 20; ++n)
    step(true);
  DOUBLES_EQUAL(cfg.pump_max_v, chain.outputs().pump_v, 0.0);
  // Steady pump: the weights sum to one (the wave phase barely moves).
  DOUBLES_EQUAL(cfg.pump_max_v, chain.outputs().pump_seen_v, 1e-3 * cfg.pump_max_v);
  step(false);  // the block that writes the pump off still saw it
  DOUBLES_EQUAL(cfg.pump_max_v, chain.outputs().pump_seen_v, 1e-3 * cfg.pump_max_v);
  for (uint32_t k = 0; k < kDecimatorOrder; ++k) {
    step(false);
    CHECK(chain.outputs().pump_seen_v < cfg.pump_max_v);
  }
  DOUBLES_EQUAL(0.0, chain.outputs().pump_seen_v, 0.0);
  // On and off from block to block: what acted, not what was written last.
  for (int n = 0; n < 12; ++n)
    step(n % 3 == 0);
}
