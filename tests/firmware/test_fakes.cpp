// SPDX-License-Identifier: MIT
#include <array>
#include <cstdint>

#include "fakes/fake_board.hpp"
#include "fakes/fake_chain.hpp"

#include "support/cpputest.hpp"

using hrg::hal::Status;

TEST_GROUP(FakeBoard){};

TEST(FakeBoard, EachAdcBlockMovesTheLockstepClockByOneBlock) {
  hrg::fakes::FakeBoard b;
  std::array<int32_t, 200> block{};
  uint64_t t = 0;
  uint32_t clipped = 9;
  CHECK(Status::ok == b.adc.read_block(block, t, clipped));
  LONGS_EQUAL(0, t);
  LONGS_EQUAL(0, clipped);
  LONGS_EQUAL(1'000'000, b.clock.now_ns());
  b.adc.skip_blocks(2);
  b.adc.read_block(block, t, clipped);
  LONGS_EQUAL(3'000'000, t);
  LONGS_EQUAL(4'000'000, b.clock.now_ns());
}

TEST(FakeBoard, AStuckAdcHoldsChannelY) {
  hrg::fakes::FakeBoard b;
  std::array<int32_t, 200> block{};
  uint64_t t = 0;
  uint32_t clipped = 0;
  b.adc.set_stuck(true);
  b.adc.read_block(block, t, clipped);
  for (std::size_t i = 1; i < block.size(); i += 2)
    LONGS_EQUAL(12345, block[i]);
  CHECK(block[0] != block[2]);
}

TEST(FakeBoard, TheDacRemembersWhichChannelsWereDriven) {
  hrg::fakes::FakeBoard b;
  std::array<int32_t, 300> block{};
  block[4] = 7;  // frame 1, forcer x
  CHECK(Status::ok == b.dac.write_block(block));
  CHECK_FALSE(b.dac.driving(0));
  CHECK(b.dac.driving(1));
  CHECK_FALSE(b.dac.driving(2));
  b.dac.set_status(Status::io_error);
  CHECK(Status::io_error == b.dac.write_block(block));
}

TEST(FakeBoard, TheCanBusHandsOutInjectedFramesInOrderAndFindsSentOnes) {
  hrg::fakes::FakeBoard b;
  hrg::hal::CanFrame f;
  CHECK(Status::would_block == b.can.receive(f));
  hrg::hal::CanFrame a, c;
  a.id = 0x81;
  c.id = 0x82;
  CHECK(b.can.inject(a));
  CHECK(b.can.inject(c));
  CHECK(Status::ok == b.can.receive(f));
  LONGS_EQUAL(0x81, f.id);
  CHECK(Status::ok == b.can.receive(f));
  LONGS_EQUAL(0x82, f.id);
  CHECK(Status::would_block == b.can.receive(f));
  b.can.send(a);
  b.can.send(c);
  CHECK(b.can.last_with_id(0x81, f));
  CHECK_FALSE(b.can.last_with_id(0x99, f));
}

TEST_GROUP(FakeChain){};

TEST(FakeChain, RingsUpToTheSetPointWhileDrivenAndDecaysWhenNot) {
  hrg::fakes::FakeChain c;
  std::array<int32_t, 200> adc{};
  std::array<int32_t, 300> dac{};
  hrg::fw::ChainCommands cmd;
  cmd.pump_on = true;
  cmd.amplitude_set_v = 0.5;
  hrg::fw::ChainRecord out;
  for (int i = 0; i < 100; ++i)
    c.process(adc, dac, cmd, out);
  DOUBLES_EQUAL(0.5, out.wave.a_A_v, 1e-12);
  LONGS_EQUAL(1000, dac[5]);
  cmd.pump_on = false;
  c.decay_per_block = 0.5;
  c.process(adc, dac, cmd, out);
  DOUBLES_EQUAL(0.25, out.wave.a_A_v, 1e-12);
}

TEST(FakeChain, MovesThePatternTowardsTheTarget) {
  hrg::fakes::FakeChain c;
  std::array<int32_t, 200> adc{};
  std::array<int32_t, 300> dac{};
  hrg::fw::ChainCommands cmd;
  cmd.pattern_control = true;
  cmd.pattern_target_rad = 0.2;
  hrg::fw::ChainRecord out;
  for (int i = 0; i < 50; ++i)
    c.process(adc, dac, cmd, out);
  DOUBLES_EQUAL(0.15, c.theta(), 1e-12);  // from 0.1 at 1e-3 per block
  for (int i = 0; i < 100; ++i)
    c.process(adc, dac, cmd, out);
  DOUBLES_EQUAL(0.2, c.theta(), 1e-12);
}

TEST_GROUP(FakeResonatorIdentifier){};

TEST(FakeResonatorIdentifier, CountsWindowsSamplesOnlyInsideAWindowAndReportsItsBackDoorValues) {
  hrg::fakes::FakeResonatorIdentifier id;
  hrg::fw::ChainRecord s;
  id.add_sample(s);  // outside a window: not counted
  id.begin_window(1.5);
  id.add_sample(s);
  id.add_sample(s);
  id.end_window();
  id.begin_window(2.0);
  id.abort_window();
  LONGS_EQUAL(2, id.samples);
  LONGS_EQUAL(2, id.begun);
  LONGS_EQUAL(1, id.ended);
  LONGS_EQUAL(1, id.aborted);
  DOUBLES_EQUAL(2.0, id.last_begin_s, 0.0);
  id.drift = 3e-4;
  id.health_ = {true, 12.0, 0.5};
  DOUBLES_EQUAL(3e-4, id.drift_rad_s(0.1, 0.0, 1.0), 0.0);
  DOUBLES_EQUAL(12.0, id.health().condition, 0.0);
  id.control_drift = -2e-5;
  DOUBLES_EQUAL(-2e-5, id.control_drift_rad_s(s), 0.0);
}
