// SPDX-License-Identifier: MIT
#include "firmware/gyro.hpp"

#include <cmath>
#include <cstdint>

#include "fakes/fake_board.hpp"
#include "fakes/fake_chain.hpp"
#include "fakes/fake_clock.hpp"

#include "support/cpputest.hpp"

using hrg::fw::Fault;
using hrg::fw::fault_bit;
using hrg::fw::Gyro;
using hrg::fw::GyroConfig;
using hrg::fw::Mode;
using hrg::fw::Pacing;

namespace {
GyroConfig test_config() {
  GyroConfig c;
  c.angular_gain = 0.5;
  c.amplitude_set_v = 1.0;
  c.self_test_frames = 20;
  c.settle_frames = 50;
  c.reacquire_frames = 5;
  c.fault_hold_frames = 100;
  c.windows.length_frames = 100;
  c.windows.period_frames = 400;
  c.windows.bins = 8;
  c.windows.windows_per_bin = 100;
  c.windows.rotate_on_static_base = false;
  c.windows.max_wait_frames = 400;
  return c;
}
}  // namespace

TEST_GROUP(Gyro) {
  hrg::fakes::FakeBoard b;
  hrg::fakes::FakeChain chain;
  hrg::fakes::FakeResonatorIdentifier ident;
  hrg::fakes::FakeClock timer;

  void run(Gyro & g, int frames) {
    for (int i = 0; i < frames; ++i)
      g.run_frame();
  }
  // Runs until `mode` is reached; returns the frames it took (or -1).
  int run_until(Gyro & g, Mode mode, int limit = 5000) {
    for (int i = 1; i <= limit; ++i) {
      g.run_frame();
      if (g.status().mode == mode) return i;
    }
    return -1;
  }
};

TEST(Gyro, PowersUpWithDrivesAndEnableOffThenRingsUpLocksAndOperates) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK(g.board_ok());
  g.run_frame();
  CHECK(Mode::power_up == g.status().mode);
  CHECK_FALSE(b.dac.driving(0));
  CHECK_FALSE(b.dac.driving(1));
  CHECK_FALSE(b.enable.level());
  // 20 clean frames of self test (frame 1 counted above)
  LONGS_EQUAL(19, run_until(g, Mode::ring_up));
  // ring-up at 0.01 V per block to 0.95 V: 95 blocks, driven from the next frame
  const int ring = run_until(g, Mode::lock);
  CHECK(ring >= 94 && ring <= 96);
  CHECK(b.enable.level());
  // 50 frames inside the bands
  LONGS_EQUAL(50, run_until(g, Mode::operate));
  CHECK(b.dac.driving(0));
  CHECK(b.dac.driving(1));
  CHECK(g.status().out_valid);
}

TEST(Gyro, OpensFreeDecayWindowsWithDrivesOffAndFeedsTheIdentifier) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK(run_until(g, Mode::operate) > 0);
  CHECK(run_until(g, Mode::free_decay, 10) > 0);  // the first window opens at once
  LONGS_EQUAL(1, ident.begun);
  g.run_frame();
  CHECK_FALSE(b.dac.driving(0));
  CHECK_FALSE(b.dac.driving(1));
  CHECK_FALSE(b.dac.driving(2));
  CHECK(b.enable.level());  // the enable line stays up: drives are zero, not disconnected
  CHECK(g.status().out_valid);
  CHECK(run_until(g, Mode::recover, 200) > 0);
  LONGS_EQUAL(1, ident.ended);
  LONGS_EQUAL(100, ident.samples);
  CHECK(run_until(g, Mode::operate, 50) > 0);
  // Over 4000 frames of operation: a window of 100 every 400 frames
  run(g, 4000);
  CHECK(ident.begun >= 10 && ident.begun <= 11);
  DOUBLES_EQUAL(0.25, g.scheduler().excitation_off_fraction(), 0.03);
  CHECK(ident.solves >= 40);  // 10 Hz over more than 4 s
}

TEST(Gyro, TheOutputAngleIsMinusTwoDeltaThetaOverK) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  auto cfg = test_config();
  CHECK(run_until(g, Mode::operate) > 0);
  const double a0 = g.status().out_angle_rad;
  // GIVEN the pattern turns by -1e-4 rad per frame for 1000 frames
  chain.theta_rate_rad_per_block = -1e-4;
  run(g, 1000);
  // THEN the output turns by +2 * 0.1 / K = 0.4 rad
  DOUBLES_EQUAL(0.4, g.status().out_angle_rad - a0, 1e-9);
  DOUBLES_EQUAL(2e-4 / cfg.angular_gain * 1000.0, g.status().out_rate_rad_s, 1e-6);
}

TEST(Gyro, TheIdentifiedDriftIsAddedToTheOutput) {
  auto cfg = test_config();
  cfg.identify = false;
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, cfg);
  CHECK(run_until(g, Mode::operate) > 0);
  const double a0 = g.status().out_angle_rad;
  ident.drift = 1e-3;  // rad/s, Omega K units (a model from calibration)
  ident.health_.solved = true;
  run(g, 1000);
  // 1 s of D / K by the trapezoid: the step of D from 0 counts half in its
  // first frame (a model update changes the slope, never the value).
  DOUBLES_EQUAL(1e-3 / 0.5 * (1.0 - 0.5e-3), g.status().out_angle_rad - a0, 1e-12);
}

TEST(Gyro, LossOfLockInOperateIsAFaultWithDrivesOffAndThenARetry) {
  auto cfg = test_config();
  cfg.identify = false;
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, cfg);
  CHECK(run_until(g, Mode::operate) > 0);
  chain.locked = false;
  const int frames = run_until(g, Mode::fault, 100);
  LONGS_EQUAL(50, frames);  // the monitor's 50-frame debounce
  CHECK(g.mode_machine().faults() & fault_bit(Fault::loss_of_lock));
  g.run_frame();
  CHECK_FALSE(b.dac.driving(0));
  CHECK_FALSE(g.status().out_valid);
  chain.locked = true;
  LONGS_EQUAL(99, run_until(g, Mode::ring_up, 200));  // 100 clean frames (one already counted)
  LONGS_EQUAL(1, g.mode_machine().retries());
}

TEST(Gyro, AnAmplitudeCollapseInFreeDecayAbortsTheWindow) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK(run_until(g, Mode::free_decay) > 0);
  chain.decay_per_block = 0.2;  // the wave dies within a few frames
  CHECK(run_until(g, Mode::fault, 50) > 0);
  LONGS_EQUAL(1, ident.aborted);
  LONGS_EQUAL(0, ident.ended);
  CHECK(g.mode_machine().faults() & fault_bit(Fault::amplitude_collapse));
}

TEST(Gyro, AStuckAdcInPowerUpEndsInSafe) {
  b.adc.set_stuck(true);
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK(run_until(g, Mode::safe, 50) > 0);
  CHECK(g.mode_machine().faults() & fault_bit(Fault::adc_stuck));
  CHECK_FALSE(b.enable.level());
}

TEST(Gyro, ADacThatFailsSendsTheGyroToSafe) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK(run_until(g, Mode::operate) > 0);
  b.dac.set_status(hrg::hal::Status::io_error);
  CHECK(run_until(g, Mode::safe, 5) > 0);
  CHECK_FALSE(b.enable.level());
}

TEST(Gyro, TheBoardFaultInputSendsTheGyroToSafeAndOnlyARestartLeavesIt) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK(run_until(g, Mode::lock) > 0);
  b.fault_in.set_level(true);
  g.run_frame();
  g.run_frame();
  CHECK(Mode::safe == g.status().mode);
  b.fault_in.set_level(false);
  run(g, 1000);
  CHECK(Mode::safe == g.status().mode);
  g.command_restart();
  CHECK(run_until(g, Mode::operate) > 0);
}

TEST(Gyro, AnOverrunStormIsAFault) {
  // A timer that, once switched to slow, advances 1 ms per reading: every task overruns.
  struct SwitchableTimer final : hrg::hal::MonotonicClock {
    mutable uint64_t t = 0;
    bool slow = false;
    uint64_t now_ns() const override { return slow ? (t += 1'000'000) : t; }
    hrg::hal::Status sleep_until_ns(uint64_t) override { return hrg::hal::Status::ok; }
  } timer2;
  auto cfg = test_config();
  cfg.identify = false;
  // (real-time pacing: in lockstep host overruns are not a fault, see below)
  b.clock.set_lockstep(false);
  Gyro g(b.board, chain, ident, timer2, Pacing::real_time, cfg);
  CHECK(run_until(g, Mode::operate) > 0);
  timer2.slow = true;
  // 16 overrun frames out of the last 64 make a storm; the monitor sees a
  // frame's overruns in the next frame, so the 17th frame raises it
  LONGS_EQUAL(17, run_until(g, Mode::fault, 100));
  CHECK(g.mode_machine().faults() & fault_bit(Fault::overrun_storm));
}

TEST(Gyro, InLockstepHostOverrunsAreCountedButAreNotAFault) {
  struct SlowTimer final : hrg::hal::MonotonicClock {
    mutable uint64_t t = 0;
    uint64_t now_ns() const override { return t += 1'000'000; }
    hrg::hal::Status sleep_until_ns(uint64_t) override { return hrg::hal::Status::ok; }
  } slow;
  Gyro g(b.board, chain, ident, slow, Pacing::lockstep, test_config());
  CHECK(run_until(g, Mode::operate) > 0);
  CHECK(g.executive().task_stats()[0].overruns > 100);
}

TEST(Gyro, SkippedAdcBlocksAreCounted) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  run(g, 5);
  b.adc.skip_blocks(3);
  run(g, 5);
  LONGS_EQUAL(3, g.status().adc_missed_blocks);
}

TEST(Gyro, APatternCommandMovesThePatternWithTheOutputHeld) {
  auto cfg = test_config();
  cfg.identify = false;
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, cfg);
  CHECK(run_until(g, Mode::operate) > 0);
  const double a0 = g.status().out_angle_rad;
  g.command_pattern_angle(0.3);
  run(g, 300);
  DOUBLES_EQUAL(0.3, chain.theta(), 1e-9);
  CHECK_FALSE(g.status().out_valid);
  DOUBLES_EQUAL(a0, g.status().out_angle_rad, 1e-12);
  g.release_pattern();
  chain.theta_rate_rad_per_block = -1e-5;
  run(g, 100);
  CHECK(g.status().out_valid);
  // The output stays held for kPatternHoldFrames after the move, then follows:
  // 80 frames of -1e-5 rad of theta, i.e. +2 * 8e-4 / K
  DOUBLES_EQUAL(a0 + 2.0 * (100 - Gyro::kPatternHoldFrames) * 1e-5 / 0.5, g.status().out_angle_rad,
                1e-9);
}

TEST(Gyro, ABoardWithAnotherBlockLayoutIsRefusedWithDrivesOff) {
  b.adc.set_layout(100'000, 50);
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK_FALSE(g.board_ok());
  run(g, 100);
  CHECK(Mode::power_up == g.status().mode);
  CHECK_FALSE(b.enable.level());
}

TEST(Gyro, SendsTheCanTelemetryAtTheProtocolsDefaultRates) {
  auto cfg = test_config();
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, cfg);
  run(g, 1000);  // one second
  uint32_t per_second = 0;
  for (const auto& m : hrg::fw::can::kTelemetry)
    per_second += m.default_rate_hz;
  // Less the first recording row (WAVE_X, WAVE_Y, ROW of frame 0): the
  // envelope's reference needs the NCO phase at the window's centre, four
  // blocks of history.
  LONGS_EQUAL(per_second - 3, b.can.counters().tx_frames);
  LONGS_EQUAL(0, g.can_tx_refused());
  DOUBLES_EQUAL(cfg.angular_gain, g.telemetry().angular_gain, 0.0);
}

TEST(Gyro, ACanSetModeSafeCommandStopsTheDrivesAndIsAcknowledged) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK(run_until(g, Mode::operate) > 0);
  b.can.inject(hrg::fw::can::encode_set_mode(Mode::safe, 1));
  CHECK(run_until(g, Mode::safe, 20) > 0);  // the command task runs at 100 Hz
  LONGS_EQUAL(1, g.commands_accepted());
  hrg::hal::CanFrame f;
  CHECK(b.can.last_with_id(hrg::fw::can::kReplyId, f));
  hrg::fw::can::Reply r;
  CHECK(hrg::fw::can::decode_reply(f, r));
  CHECK(hrg::fw::can::CommandResult::accepted == r.result);
  LONGS_EQUAL(1, r.counter);
  g.run_frame();
  CHECK_FALSE(b.enable.level());
  // AND a ring-up command brings it back through power-up
  b.can.inject(hrg::fw::can::encode_set_mode(Mode::ring_up, 2));
  CHECK(run_until(g, Mode::operate) > 0);
}

TEST(Gyro, ACorruptedCommandIsRefusedAndChangesNothing) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  CHECK(run_until(g, Mode::operate) > 0);
  auto f = hrg::fw::can::encode_set_mode(Mode::safe, 1);
  f.data[0] ^= 0x01;  // the CRC no longer matches
  b.can.inject(f);
  run(g, 20);
  CHECK(Mode::safe != g.status().mode);
  LONGS_EQUAL(0, g.commands_accepted());
  LONGS_EQUAL(1, g.commands_refused());
}

TEST(Gyro, CanCommandsSetTheAgcSetPointAndTheWindowTiming) {
  auto cfg = test_config();
  cfg.identify = false;  // settings are refused during a free-decay window
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, cfg);
  CHECK(run_until(g, Mode::operate) > 0);
  b.can.inject(hrg::fw::can::encode_agc(1.1, 1));
  b.can.inject(hrg::fw::can::encode_window(2.0, 0.25, 2));
  run(g, 20);
  LONGS_EQUAL(2, g.commands_accepted());
  DOUBLES_EQUAL(1.1, g.config().amplitude_set_v, 1e-3);
  DOUBLES_EQUAL(1.1, chain.last_commands().amplitude_set_v, 1e-3);
  LONGS_EQUAL(2000, g.scheduler().config().period_frames);
  LONGS_EQUAL(250, g.scheduler().config().length_frames);
}

TEST(Gyro, ReadsTheTemperatureSensorAt100HzAndPassesItToTheIdentifierAndTelemetry) {
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, test_config());
  // GIVEN a board without a sensor: no temperature, nothing counted as an error
  run(g, 1000);
  LONGS_EQUAL(100, b.temperature.reads());
  CHECK_FALSE(g.status().temp_valid);
  CHECK_FALSE(ident.temp_valid);
  LONGS_EQUAL(0, g.status().temp_errors);
  // WHEN the sensor reads 26.5 degC
  b.temperature.set(26.5);
  run(g, 100);
  // THEN the firmware reports it and the identifier refers its model to it
  CHECK(g.status().temp_valid);
  DOUBLES_EQUAL(26.5, g.status().temp_c, 0.0);
  DOUBLES_EQUAL(26.5, ident.temp_c, 0.0);
  CHECK(ident.temp_valid);
  DOUBLES_EQUAL(26.5, g.telemetry().temp_c, 0.0);
  // WHEN a read fails, the value is no longer used (the model's reference
  // temperature is, not a stale reading) and the failure is counted
  b.temperature.set(99.0, hrg::hal::Status::io_error);
  run(g, 10);
  CHECK_FALSE(g.status().temp_valid);
  CHECK_FALSE(ident.temp_valid);
  LONGS_EQUAL(1, g.status().temp_errors);
  // WHEN it only has no new conversion yet, the last reading stays
  b.temperature.set(27.0);
  run(g, 10);
  b.temperature.set(0.0, hrg::hal::Status::would_block);
  run(g, 10);
  CHECK(g.status().temp_valid);
  DOUBLES_EQUAL(27.0, ident.temp_c, 0.0);
}

TEST(Gyro, TheReadoutsOwnPatternWithholdsDPhiAndTheStatusSaysWhy) {
  using hrg::fw::CompensationReason;
  using hrg::fw::reason_bit;
  auto cfg = test_config();
  cfg.identify = false;  // a model from calibration: in force once solved, no check windows
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, cfg);
  ident.control_drift = 2e-4;  // rad/s: what the D_Phi fits read
  CHECK(run_until(g, Mode::operate) > 0);
  // GIVEN no model yet: not valid, because not in force
  LONGS_EQUAL(reason_bit(CompensationReason::not_in_force), g.status().compensation_reasons);
  // WHEN the model is solved and the readout shows no pattern
  ident.health_.solved = true;
  ident.health_.readout_pattern_sigmas = 4.9;
  run(g, 100);
  // THEN D_Phi is added and the compensation is valid with no reason against it
  DOUBLES_EQUAL(2e-4, g.status().control_drift_rad_s, 0.0);
  DOUBLES_EQUAL(0.0, g.status().control_drift_withheld_rad_s, 0.0);
  CHECK(g.status().compensation_valid);
  LONGS_EQUAL(0, g.status().compensation_reasons);
  // WHEN the pickoff self-identification's gain stands 5.1 sigmas out
  ident.health_.readout_pattern_sigmas = 5.1;
  run(g, 100);
  // THEN D_Phi is withheld and said so; with no pump D_Phi in use nothing
  // measured is missing, so the compensation stays valid
  const uint8_t withheld = reason_bit(CompensationReason::control_drift_withheld);
  DOUBLES_EQUAL(0.0, g.status().control_drift_rad_s, 0.0);
  DOUBLES_EQUAL(2e-4, g.status().control_drift_withheld_rad_s, 0.0);
  LONGS_EQUAL(withheld, g.status().compensation_reasons);
  CHECK(g.status().compensation_valid);
  // WHEN the pump's D_Phi was in use: the output misses it, not valid
  ident.health_.pump_drift_in_use = true;
  run(g, 100);
  CHECK_FALSE(g.status().compensation_valid);
  LONGS_EQUAL(withheld, g.status().compensation_reasons);
  // WHEN instead the model's damping anisotropy is the readout's (6.5 sigmas)
  ident.health_.pump_drift_in_use = false;
  ident.health_.readout_pattern_sigmas = 0.0;
  ident.health_.readout_damping_sigmas = 6.5;
  run(g, 100);
  // THEN not valid, both reasons, and the figure on the status and the bus
  const uint8_t both = reason_bit(CompensationReason::readout_in_damping) | withheld;
  CHECK_FALSE(g.status().compensation_valid);
  LONGS_EQUAL(both, g.status().compensation_reasons);
  DOUBLES_EQUAL(0.0, g.status().control_drift_rad_s, 0.0);
  DOUBLES_EQUAL(6.5, g.status().readout_damping_sigmas, 0.0);
  LONGS_EQUAL(both, g.telemetry().comp_reasons);
  DOUBLES_EQUAL(6.5, g.telemetry().readout_damping_sigmas, 0.0);
  CHECK_FALSE(g.telemetry().comp_valid);
  // WHEN both figures fall back within their limits, D_Phi is added again
  ident.health_.readout_damping_sigmas = 4.0;
  run(g, 100);
  DOUBLES_EQUAL(2e-4, g.status().control_drift_rad_s, 0.0);
  LONGS_EQUAL(0, g.status().compensation_reasons);
  CHECK(g.status().compensation_valid);
}

TEST(Gyro, AReadoutPhaseWhoseDriftCouldOutweighTheCompensationMakesItNotValid) {
  using hrg::fw::CompensationReason;
  using hrg::fw::reason_bit;
  auto cfg = test_config();
  cfg.identify = false;  // a model from calibration: in force once solved, no check windows
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, cfg);
  CHECK(run_until(g, Mode::operate) > 0);
  ident.health_.solved = true;
  // GIVEN a phase lag 31000 sigmas out whose drift 2 nu phi is 0.4 of the
  // model's (the compensated output cannot be worse than raw)
  ident.health_.readout_phase_sigmas = 31000.0;
  ident.health_.readout_phase_drift_share = 0.4;
  run(g, 100);
  // THEN the compensation stays valid
  CHECK(g.status().compensation_valid);
  LONGS_EQUAL(0, g.status().compensation_reasons);
  // WHEN its drift is more than half the model's (1 deg on the 4.2 kHz
  // resonator of tools/gregory/README.md: 1.16)
  ident.health_.readout_phase_drift_share = 1.16;
  run(g, 100);
  // THEN not valid, and said why, on the status and the bus
  const uint8_t phase = reason_bit(CompensationReason::readout_phase_drift);
  CHECK_FALSE(g.status().compensation_valid);
  LONGS_EQUAL(phase, g.status().compensation_reasons);
  LONGS_EQUAL(phase, g.telemetry().comp_reasons);
  CHECK_FALSE(g.telemetry().comp_valid);
  // WHEN the phase stands within 5 sigmas (noise, whatever its share)
  ident.health_.readout_phase_sigmas = 4.9;
  run(g, 100);
  // THEN valid again
  CHECK(g.status().compensation_valid);
  LONGS_EQUAL(0, g.status().compensation_reasons);
}
