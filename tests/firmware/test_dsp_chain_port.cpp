// SPDX-License-Identifier: MIT
// The firmware's adapter over dsp::Chain: configuration from the converters,
// configuration errors, separate drive gating and the pattern-rate limit.
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "fakes/fake_board.hpp"
#include "fakes/fake_chain.hpp"
#include "firmware/dsp_chain_port.hpp"
#include "firmware/gyro.hpp"

#include "support/cpputest.hpp"

using hrg::dsp::ChainConfig;
using hrg::fw::ChainCommands;
using hrg::fw::ChainRecord;
using hrg::fw::DspChainPort;

namespace {
constexpr double kPi = std::numbers::pi;
constexpr std::size_t kFrames = 100;

// One ADC block of a standing wave x = a cos(w t) on the x pickoff.
void wave_block(std::array<int32_t, 2 * kFrames>& adc, uint64_t block, double a_v, double fs_v) {
  for (std::size_t j = 0; j < kFrames; ++j) {
    const double n = static_cast<double>(block * kFrames + j);
    const double x = a_v / fs_v * std::cos(2.0 * kPi * 5000.0 * n / 100000.0);
    adc[2 * j] = static_cast<int32_t>(std::lround(x * 2147483647.0));
    adc[2 * j + 1] = 0;
  }
}

struct Drive {
  double pump_rms = 0.0;
  double forcer_rms = 0.0;
};

Drive run_blocks(DspChainPort& port, const ChainCommands& cmd, double a_v, double fs_v,
                 int blocks) {
  std::array<int32_t, 2 * kFrames> adc{};
  std::array<int32_t, 3 * kFrames> dac{};
  ChainRecord out;
  Drive d;
  for (int b = 0; b < blocks; ++b) {
    wave_block(adc, static_cast<uint64_t>(b), a_v, fs_v);
    port.process(adc, dac, cmd, out);
  }
  for (std::size_t j = 0; j < kFrames; ++j) {
    d.pump_rms += std::pow(static_cast<double>(dac[3 * j]), 2);
    d.forcer_rms += std::pow(static_cast<double>(dac[3 * j + 1]), 2) +
                    std::pow(static_cast<double>(dac[3 * j + 2]), 2);
  }
  d.pump_rms = std::sqrt(d.pump_rms / kFrames) / 2147483648.0;
  d.forcer_rms = std::sqrt(d.forcer_rms / kFrames) / 2147483648.0;
  return d;
}
}  // namespace

TEST_GROUP(DspChainPort){};

TEST(DspChainPort, TheChainConfigurationComesFromTheConverters) {
  hrg::fw::ConverterLayout conv;
  conv.adc_full_scale_v = 2.5;
  conv.dac_full_scale_v = 10.0;
  conv.dac_latency_samples = 2.0;
  const ChainConfig c = hrg::fw::chain_config_for(conv);
  DOUBLES_EQUAL(2.5, c.adc_full_scale_v, 0.0);
  // One block of double buffering, half a frame of hold, two of pipeline.
  DOUBLES_EQUAL(100.0 + 0.5 + 2.0, c.dac_lead_frames, 0.0);
  CHECK(hrg::dsp::check_chain_config(c) == nullptr);
}

TEST(DspChainPort, AnUnusableConfigurationIsNamedAndKeepsTheDrivesAtZero) {
  ChainConfig c;
  c.f_max_hz = c.f_min_hz - 1.0;
  DspChainPort port(c);
  CHECK_FALSE(port.usable());
  STRCMP_CONTAINS("f_max_hz", port.error());
  ChainCommands cmd;
  cmd.pump_on = cmd.forcers_on = true;
  const Drive d = run_blocks(port, cmd, 0.5, c.adc_full_scale_v, 3);
  DOUBLES_EQUAL(0.0, d.pump_rms, 0.0);
  DOUBLES_EQUAL(0.0, d.forcer_rms, 0.0);
}

TEST(DspChainPort, PumpAndForcersAreGatedSeparately) {
  // A 0.5 V wave (half the set point): ring-up, where the pump runs at its
  // limit (10 V of a 10 V DAC, rms 1/sqrt 2) and the forcers at 5 V along
  // the pattern (rms 0.5/sqrt 2 of full scale).
  ChainConfig c;
  ChainCommands forcers_only;
  forcers_only.forcers_on = true;
  DspChainPort a(c);
  const Drive fa = run_blocks(a, forcers_only, 0.5, c.adc_full_scale_v, 20);
  DOUBLES_EQUAL(0.0, fa.pump_rms, 0.0);
  DOUBLES_EQUAL(0.5 / std::sqrt(2.0), fa.forcer_rms, 0.01);

  ChainCommands pump_only;
  pump_only.pump_on = true;
  DspChainPort b(c);
  const Drive pb = run_blocks(b, pump_only, 0.5, c.adc_full_scale_v, 20);
  DOUBLES_EQUAL(0.0, pb.forcer_rms, 0.0);
  DOUBLES_EQUAL(1.0 / std::sqrt(2.0), pb.pump_rms, 0.01);
}

TEST(DspChainPort, ThePatternRateIsClampedToWhatTheForcersCanDo) {
  // theta_A' = g u_r / (4 w a_A): 200 * 5 / (4 * 2 pi 5000 * 1 V) = 7.96e-3
  // rad/s (0.456 deg/s) at full forcer voltage, 80 % of it left to the command.
  ChainConfig c;
  const double full = 200.0 * 5.0 / (4.0 * 2.0 * kPi * 5000.0 * 1.0);
  DOUBLES_EQUAL(0.8 * full, hrg::fw::max_pattern_rate_rad_s(c), 1e-12);
  DspChainPort fast(c, 0.5);
  DOUBLES_EQUAL(0.8 * full, fast.pattern_max_rate_rad_s(), 1e-12);
  DspChainPort slow(c, 1e-3);
  DOUBLES_EQUAL(1e-3, slow.pattern_max_rate_rad_s(), 0.0);
  DspChainPort derived(c);
  DOUBLES_EQUAL(0.8 * full, derived.pattern_max_rate_rad_s(), 1e-12);
}

TEST(DspChainPort, TheHalConverterInfoGivesTheSameConfiguration) {
  const hrg::hal::ConverterInfo adc{100000, 100, 2.5};
  const hrg::hal::ConverterInfo dac{100000, 100, 10.0};
  const ChainConfig c = hrg::fw::chain_config_for(hrg::fw::converter_layout(adc, dac, 2.0));
  DOUBLES_EQUAL(2.5, c.adc_full_scale_v, 0.0);
  DOUBLES_EQUAL(10.0, c.dac_full_scale_v, 0.0);
  DOUBLES_EQUAL(102.5, c.dac_lead_frames, 0.0);
  LONGS_EQUAL(100, c.block_frames);
}

TEST(DspChainPort, TheGyroRefusesAnUnusableChainAndKeepsTheDrivesOff) {
  ChainConfig c;
  c.pump_max_v = -1.0;
  DspChainPort port(c);
  hrg::fakes::FakeBoard b;
  hrg::fakes::FakeClock timer;
  hrg::fakes::FakeResonatorIdentifier ident;
  hrg::fw::Gyro g(b.board, port, ident, timer, hrg::fw::Pacing::lockstep, hrg::fw::GyroConfig{});
  CHECK_FALSE(g.board_ok());
  STRCMP_CONTAINS("pump_max_v", g.chain_error());
  for (int i = 0; i < 100; ++i)
    g.run_frame();
  CHECK(hrg::fw::Mode::power_up == g.status().mode);
  CHECK_FALSE(g.status().excitation_on);
}
