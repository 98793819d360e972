// SPDX-License-Identifier: MIT
// CanLink over a fake bus: every command is answered, one accepted command per
// poll, refusals are dropped, telemetry refusals are counted, and bus-off is
// left by a restart after the configured number of frames. The fake has tests
// of its own first.
#include "fakes/fake_can.hpp"
#include "firmware/can/link.hpp"

#include "support/cpputest.hpp"

using namespace hrg::fw::can;
using hrg::fakes::FakeCan;
using hrg::fw::Mode;
using hrg::hal::CanFrame;
using hrg::hal::CanState;
using hrg::hal::Status;

TEST_GROUP(FakeCan) { FakeCan bus; };

TEST(FakeCan, ReceivesWhatTheBackDoorQueuedInOrder) {
  CanFrame a;
  a.id = 1;
  CanFrame b;
  b.id = 2;
  bus.inject(a);
  bus.inject(b);
  CanFrame f;
  CHECK(Status::ok == bus.receive(f));
  LONGS_EQUAL(1, f.id);
  CHECK(Status::ok == bus.receive(f));
  LONGS_EQUAL(2, f.id);
  CHECK(Status::would_block == bus.receive(f));
}

TEST(FakeCan, RefusesSendsWhenToldAndWhileBusOff) {
  CanFrame f;
  bus.set_send_result(Status::would_block);
  CHECK(Status::would_block == bus.send(f));
  LONGS_EQUAL(1, bus.counters().tx_queue_full);
  bus.set_send_result(Status::ok);
  bus.set_state(CanState::bus_off);
  CHECK(Status::bus_off == bus.send(f));
  CHECK(Status::ok == bus.restart());
  CHECK(Status::ok == bus.send(f));
  LONGS_EQUAL(1, bus.sent_count());
}

TEST_GROUP(CanLink) {
  FakeCan bus;
  CanLink link{bus, 100};
  ControllerView operating() {
    ControllerView v;
    v.mode = Mode::operate;
    v.agc_setpoint_v = 1.0;
    return v;
  }
  Reply last_reply() {
    Reply r;
    CHECK(bus.sent_count() > 0);
    CHECK(decode_reply(bus.last(), r));
    return r;
  }
};

TEST(CanLink, InitAcceptsOnlyTheCommandRangeAndTheCalibrationService) {
  CHECK(Status::ok == link.init());
  LONGS_EQUAL(2, bus.filters().size());
  LONGS_EQUAL(0x080, bus.filters()[0].id);
  LONGS_EQUAL(0x7F0, bus.filters()[0].mask);
  LONGS_EQUAL(0x0A0, bus.filters()[1].id);
  LONGS_EQUAL(0x7F8, bus.filters()[1].mask);
}

TEST(CanLink, CalibrationFramesGoToTheTransferAndAreAnsweredNotReturnedAsCommands) {
  // A seed request in the service mode: answered with a seed, no command.
  ControllerView safe;
  safe.mode = Mode::safe;
  bus.inject(encode_cal_seed_request());
  Command c;
  CHECK_FALSE(link.poll(safe, c, 1000, 77));
  CalReply r;
  CHECK(decode_cal_reply(bus.last(), r));
  CHECK(CalStep::seed == r.step);
  CHECK(CalResult::accepted == r.result);
  CHECK(r.value != 0);
  CHECK(link.calibration().unlocked() == false);
  // While operating the same request is refused, still answered by the link.
  bus.inject(encode_cal_seed_request());
  CHECK_FALSE(link.poll(operating(), c, 1001, 78));
  CHECK(decode_cal_reply(bus.last(), r));
  CHECK(CalResult::wrong_state == r.result);
  LONGS_EQUAL(0, link.stats().commands_accepted + link.stats().commands_refused);
}

TEST(CanLink, AnAcceptedCommandIsReturnedAndAnswered) {
  bus.inject(encode_agc(1.1, 1));
  Command c;
  CHECK(link.poll(operating(), c));
  CHECK(c.id == Cmd::agc);
  DOUBLES_EQUAL(1.1, c.agc_setpoint_v, 1e-9);
  LONGS_EQUAL(static_cast<int>(CommandResult::accepted), static_cast<int>(last_reply().result));
  LONGS_EQUAL(1, link.stats().commands_accepted);
}

TEST(CanLink, RefusedCommandsAreAnsweredAndDroppedAndTheNextIsReturned) {
  CanFrame bad = encode_agc(1.1, 1);
  bad.data[0] ^= 1;  // checksum now wrong
  bus.inject(bad);
  CanFrame telemetry;
  telemetry.id = 0x100;  // not a command: no reply
  bus.inject(telemetry);
  bus.inject(encode_status_request(2));
  Command c;
  CHECK(link.poll(operating(), c));
  CHECK(c.id == Cmd::status_request);
  LONGS_EQUAL(2, bus.sent_count());  // two replies
  Reply r;
  CHECK(decode_reply(bus.sent(0), r));
  LONGS_EQUAL(static_cast<int>(CommandResult::bad_checksum), static_cast<int>(r.result));
  LONGS_EQUAL(1, link.stats().commands_refused);
}

TEST(CanLink, OneCommandPerPollSoTheNextSeesTheAppliedState) {
  bus.inject(encode_ident(true, 1));
  bus.inject(encode_ident(true, 2));
  Command c;
  CHECK(link.poll(operating(), c));
  // The firmware applied the first: identification now runs, so a second
  // start is refused against the new state.
  ControllerView running = operating();
  running.ident_active = true;
  CHECK_FALSE(link.poll(running, c));
  LONGS_EQUAL(static_cast<int>(CommandResult::wrong_state), static_cast<int>(last_reply().result));
}

TEST(CanLink, TelemetryRefusedByAFullQueueIsCountedNotQueued) {
  CanFrame frames[3];
  bus.set_send_result(Status::would_block);
  link.send(frames);
  LONGS_EQUAL(3, link.stats().tx_refused);
  LONGS_EQUAL(3, bus.counters().tx_queue_full);
  bus.set_send_result(Status::ok);
  link.send(frames);
  LONGS_EQUAL(3, link.stats().tx_refused);
  LONGS_EQUAL(3, bus.sent_count());
}

TEST(CanLink, BusOffIsLeftByOneRestartAfterTheConfiguredFrames) {
  bus.set_state(CanState::bus_off);
  for (int k = 0; k < 99; ++k)
    link.service();
  LONGS_EQUAL(0, bus.restart_calls());
  link.service();  // the 100th frame off the bus
  LONGS_EQUAL(1, bus.restart_calls());
  CHECK(CanState::error_active == bus.state());
  for (int k = 0; k < 500; ++k)
    link.service();
  LONGS_EQUAL(1, bus.restart_calls());
  LONGS_EQUAL(1, link.stats().restarts);
}
