// SPDX-License-Identifier: MIT
// A calibration written over CAN into the firmware on the simulated target:
// the host's sender (hrg can-calibrate's) against the firmware's CAN link.
// The block is applied (the firmware's calibration has the file's CRC-32)
// only through the whole guarded write, and each refusal is refused on the
// link too, leaving the calibration in force unchanged.
#include <memory>
#include <string>

#include "can/calibration_sender.hpp"
#include "firmware/app/firmware.hpp"
#include "firmware/calibration_file.hpp"
#include "sim_target/control.hpp"
#include "sim_run/console.hpp"
#include "sim_run/run.hpp"

#include "support/cpputest.hpp"

using namespace hrg;
using fw::can::CalResult;
using fw::can::CalStep;

namespace {

fw::can::CalSecret secret() {
  fw::can::CalSecret s{};
  for (std::size_t i = 0; i < s.size(); ++i)
    s[i] = static_cast<uint8_t>(0x3Cu + 11u * i);
  return s;
}

// The firmware in lockstep on the simulated target; the host's frames go in
// through the target's receive queue, the firmware's replies come out of
// what it sent, one base frame (1 ms) at a time.
struct Bench final : can::CalBusIo {
  sim_run::RunConfig job = sim_run::default_run(60.0);
  std::unique_ptr<sim::SimTarget> target = std::make_unique<sim::SimTarget>();
  sim_run::HostClock timer;
  std::unique_ptr<fw::app::Firmware> firmware;

  Bench() {
    job.firmware.gyro.calibration_service.secret = secret();
    target->configure(job.sim);
    firmware = std::make_unique<fw::app::Firmware>(target->board(), timer, fw::Pacing::lockstep,
                                                   job.firmware);
  }
  void run(int frames) {
    for (int k = 0; k < frames; ++k)
      firmware->run_frame();
  }
  void send(const hal::CanFrame& f) override { target->can().inject_rx(f); }
  bool wait_reply(fw::can::CalReply& r, uint32_t timeout_ms) override {
    for (uint32_t k = 0; k <= timeout_ms; ++k) {
      for (const auto& f : target->can().sent()) {
        if (fw::can::decode_cal_reply(f, r)) {
          target->can().clear_sent();
          return true;
        }
      }
      target->can().clear_sent();
      if (k < timeout_ms) run(1);
    }
    return false;
  }
  void pause(uint32_t ms) override { run(static_cast<int>(ms)); }
  uint32_t crc_in_force() const { return fw::calibration_crc(firmware->calibration()); }
};

fw::Calibration file_calibration() {
  return fw::load_calibration(std::string(std::getenv("HRG_SOURCE_DIR")) +
                              "/tests/calibration/gyro_example.toml")
      .calibration;
}

}  // namespace

TEST_GROUP_WITHOUT_LEAK_CHECK(CanCalibrate);

TEST(CanCalibrate, AFileWrittenInTheServiceModeIsAppliedWithItsCrc) {
  Bench b;
  b.run(100);
  b.firmware->gyro().command_safe();
  b.run(20);
  CHECK(fw::Mode::safe == b.firmware->gyro().status().mode);
  const fw::Calibration cal = file_calibration();
  CHECK(fw::calibration_crc(cal) != b.crc_in_force());
  const can::CalWriteResult r = can::write_calibration(b, cal, secret());
  CHECK_TEXT(r.applied(), fw::can::to_string(r.reply.result));
  // The reply carries the CRC now in force: the file's, and the firmware's.
  LONGS_EQUAL(fw::calibration_crc(cal), r.reply.value);
  LONGS_EQUAL(fw::calibration_crc(cal), b.crc_in_force());
  LONGS_EQUAL(1, b.firmware->gyro().can_link().calibration().applied_count());
  // One write per unlock: the same block again needs a new unlock.
  b.send(fw::can::encode_cal_start(static_cast<uint16_t>(fw::kCalibrationBytes), 0));
  fw::can::CalReply again;
  CHECK(b.wait_reply(again, 10));
  CHECK(CalResult::locked == again.result);
}

TEST(CanCalibrate, EveryRefusalOnTheLinkLeavesTheCalibrationInForce) {
  Bench b;
  b.run(100);
  const uint32_t before = b.crc_in_force();
  const fw::Calibration cal = file_calibration();
  // Outside the service mode (the gyro is ringing up).
  can::CalWriteResult r = can::write_calibration(b, cal, secret());
  CHECK(r.answered && CalResult::wrong_state == r.reply.result);
  b.firmware->gyro().command_safe();
  b.run(20);
  struct Case {
    const char* what;
    can::CalWriteFaults faults;
    CalStep step;
    CalResult result;
  };
  can::CalWriteFaults wrong_key, wrong_crc, gap, short_block, stale;
  wrong_key.wrong_key = true;
  wrong_crc.wrong_block_crc = true;
  gap.skip_data_seq = 4;
  short_block.stop_after_data = 10;
  stale.pause_before_end_ms = 600;
  const Case cases[] = {
      {"wrong key", wrong_key, CalStep::key, CalResult::bad_key},
      {"block CRC", wrong_crc, CalStep::end, CalResult::crc_mismatch},
      {"gap in the data", gap, CalStep::data, CalResult::bad_sequence},
      {"END too early", short_block, CalStep::end, CalResult::incomplete},
      {"stale block", stale, CalStep::timeout, CalResult::stale},
  };
  for (const Case& c : cases) {
    r = can::write_calibration(b, cal, secret(), c.faults);
    CHECK_TEXT(r.answered, c.what);
    CHECK_TEXT(c.step == r.reply.step, c.what);
    CHECK_TEXT(c.result == r.reply.result, c.what);
    LONGS_EQUAL_TEXT(before, b.crc_in_force(), c.what);
    // Let the replies to what followed a refusal (locked DATA frames) pass.
    b.run(50);
    b.target->can().clear_sent();
  }
  // A field outside its range (a gain of 50 %, field 0) is refused whole.
  fw::Calibration bad = cal;
  bad.pickoff_y_gain = 0.5;
  r = can::write_calibration(b, bad, secret());
  CHECK(CalResult::out_of_range == r.reply.result);
  LONGS_EQUAL(0, r.reply.detail);
  LONGS_EQUAL(before, b.crc_in_force());
  // And after all that, a good write still goes through.
  r = can::write_calibration(b, cal, secret());
  CHECK(r.applied());
  LONGS_EQUAL(fw::calibration_crc(cal), b.crc_in_force());
}
