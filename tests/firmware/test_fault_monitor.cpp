// SPDX-License-Identifier: MIT
#include "firmware/fault_monitor.hpp"

#include <array>
#include <cstdint>

#include "support/cpputest.hpp"

using hrg::fw::Fault;
using hrg::fw::fault_bit;
using hrg::fw::FaultMonitor;
using hrg::fw::Mode;
using hrg::fw::MonitorInputs;

namespace {
MonitorInputs healthy() {
  MonitorInputs in;
  in.amplitude_v = 1.0;
  in.pll_locked = true;
  in.adc_samples = 200;
  return in;
}
}  // namespace

TEST_GROUP(FaultMonitor){};

TEST(FaultMonitor, AHealthyGyroRaisesNothing) {
  FaultMonitor mon;
  for (int i = 0; i < 100; ++i)
    LONGS_EQUAL(0, mon.update(healthy(), Mode::operate));
}

TEST(FaultMonitor, LossOfLockNeedsItsFrameCountInOperate) {
  FaultMonitor mon;  // 50 frames
  auto in = healthy();
  in.pll_locked = false;
  for (int i = 0; i < 49; ++i)
    LONGS_EQUAL(0, mon.update(in, Mode::operate));
  LONGS_EQUAL(fault_bit(Fault::loss_of_lock), mon.update(in, Mode::operate));
}

TEST(FaultMonitor, LossOfLockIsNotAFaultWhileLockingOrInFreeDecay) {
  FaultMonitor mon;
  auto in = healthy();
  in.pll_locked = false;
  for (int i = 0; i < 200; ++i) {
    LONGS_EQUAL(0, mon.update(in, Mode::lock));
    LONGS_EQUAL(0, mon.update(in, Mode::free_decay));
  }
}

TEST(FaultMonitor, AmplitudeBelowTheCollapseFractionIsAFaultOnceRungUp) {
  FaultMonitor mon;  // set point 1 V, collapse below 0.3 V
  auto in = healthy();
  in.amplitude_v = 0.31;
  LONGS_EQUAL(0, mon.update(in, Mode::operate));
  in.amplitude_v = 0.29;
  LONGS_EQUAL(fault_bit(Fault::amplitude_collapse), mon.update(in, Mode::free_decay));
  LONGS_EQUAL(0, mon.update(in, Mode::ring_up));  // ringing up from rest is not a collapse
}

TEST(FaultMonitor, SaturationNeedsMoreThanOnePercentClippedForFiveBlocks) {
  FaultMonitor mon;
  auto in = healthy();
  in.adc_clipped = 2;  // exactly 1 %: not saturated
  for (int i = 0; i < 10; ++i)
    LONGS_EQUAL(0, mon.update(in, Mode::operate));
  in.adc_clipped = 3;
  for (int i = 0; i < 4; ++i)
    LONGS_EQUAL(0, mon.update(in, Mode::operate));
  LONGS_EQUAL(fault_bit(Fault::adc_saturation), mon.update(in, Mode::operate));
}

TEST(FaultMonitor, StuckNeedsTenConsecutiveBlocks) {
  FaultMonitor mon;
  auto in = healthy();
  in.adc_stuck = true;
  for (int i = 0; i < 9; ++i)
    LONGS_EQUAL(0, mon.update(in, Mode::power_up));
  in.adc_stuck = false;
  LONGS_EQUAL(0, mon.update(in, Mode::power_up));  // the count restarts
  in.adc_stuck = true;
  for (int i = 0; i < 9; ++i)
    LONGS_EQUAL(0, mon.update(in, Mode::power_up));
  LONGS_EQUAL(fault_bit(Fault::adc_stuck), mon.update(in, Mode::power_up));
}

TEST(FaultMonitor, SixteenOverrunFramesOutOfSixtyFourIsAStorm) {
  FaultMonitor mon;
  auto in = healthy();
  in.recent_overruns = 15;
  LONGS_EQUAL(0, mon.update(in, Mode::operate));
  in.recent_overruns = 16;
  LONGS_EQUAL(fault_bit(Fault::overrun_storm), mon.update(in, Mode::operate));
}

TEST(FaultMonitor, ExternalAndDacFaultsPassStraightThrough) {
  FaultMonitor mon;
  auto in = healthy();
  in.external_fault = true;
  in.dac_error = true;
  LONGS_EQUAL(fault_bit(Fault::external) | fault_bit(Fault::dac_fault),
              mon.update(in, Mode::operate));
}

TEST_GROUP(AdcBlockStuck){};

TEST(AdcBlockStuck, AChannelHoldingOneValueIsStuck) {
  std::array<int32_t, 8> block{1, 5, 2, 5, 3, 5, 4, 5};  // y holds 5
  CHECK(hrg::fw::adc_block_stuck(block, 2));
}

TEST(AdcBlockStuck, MovingChannelsAreNotStuck) {
  std::array<int32_t, 8> block{1, 5, 2, 6, 3, 5, 4, 5};
  CHECK_FALSE(hrg::fw::adc_block_stuck(block, 2));
}
