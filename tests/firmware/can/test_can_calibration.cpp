// SPDX-License-Identifier: MIT
// The guarded calibration write over CAN: the whole exchange, and every
// refusal path changing nothing and being counted.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "firmware/calibration.hpp"
#include "firmware/can/calibration_transfer.hpp"

#include "support/cpputest.hpp"

using namespace hrg::fw;
using namespace hrg::fw::can;
using hrg::hal::CanFrame;

namespace {

constexpr uint16_t kBlockBytes = static_cast<uint16_t>(kCalibrationBytes);
constexpr unsigned kDataFrames =
    (kCalibrationBytes + kCalDataBytesPerFrame - 1) / kCalDataBytesPerFrame;

CalTransferConfig config() {
  CalTransferConfig c;
  for (uint8_t i = 0; i < 16; ++i)
    c.secret[i] = static_cast<uint8_t>(0xA0u + 7u * i);
  return c;
}

Calibration new_calibration() {
  Calibration c;
  c.pickoff_y_gain = 0.0101;
  c.pickoff_y_misalignment_rad = 0.5 * kDegToRad;
  c.feedthrough_x_re_v_per_v = 8.66e-4;
  return c;
}

// A host and the gyro's transfer object, with a clock.
struct Rig {
  CalibrationTransfer gyro{config(), kIdentityCalibration};
  uint32_t now_ms = 1000;
  Mode mode = Mode::safe;
  uint32_t entropy = 12345;
  std::vector<CalReply> replies;

  CalTransferOutcome send(const CanFrame& f) {
    const CalTransferOutcome o = gyro.process(f, mode, now_ms, entropy++);
    if (o.reply_ready) {
      CalReply r;
      CHECK_TRUE(decode_cal_reply(o.reply, r));
      replies.push_back(r);
    }
    return o;
  }
  CalReply last() const { return replies.back(); }

  // Seed, key; returns the key reply.
  CalReply unlock(const CalSecret& secret = config().secret) {
    send(encode_cal_seed_request());
    const CalReply seed = last();
    CHECK_EQUAL(static_cast<int>(CalResult::accepted), static_cast<int>(seed.result));
    send(encode_cal_key(calibration_key(seed.value, secret)));
    return last();
  }
  void send_data(const CalibrationBytes& b, unsigned from_frame = 0,
                 unsigned to_frame = kDataFrames) {
    for (unsigned k = from_frame; k < to_frame; ++k) {
      const unsigned at = kCalDataBytesPerFrame * k;
      const unsigned n = std::min<unsigned>(kCalDataBytesPerFrame, kCalibrationBytes - at);
      const CalTransferOutcome o = send(encode_cal_data(static_cast<uint8_t>(k), b.data() + at, n));
      if (o.reply_ready) return;
      now_ms += 1;
    }
  }
  // A whole block; returns END's reply.
  CalReply write(const CalibrationBytes& b, uint32_t crc) {
    send(encode_cal_start(static_cast<uint16_t>(b.size()), crc));
    send_data(b);
    send(encode_cal_end());
    return last();
  }
  uint32_t count(CalResult r) const { return gyro.counts()[static_cast<std::size_t>(r)]; }
  void expect_unchanged() const {
    CHECK_EQUAL(calibration_crc(kIdentityCalibration), gyro.active_crc());
    CHECK_EQUAL(0u, gyro.applied_count());
    DOUBLES_EQUAL(0.0, gyro.active().pickoff_y_gain, 0.0);
  }
};

int result_of(const CalReply& r) { return static_cast<int>(r.result); }
constexpr int kAccepted = static_cast<int>(CalResult::accepted);

}  // namespace

TEST_GROUP(CalibrationKey){};

TEST(CalibrationKey, SipHashMatchesThePapersTestVector) {
  // SipHash-2-4, key 00..0f, message 00..0e: a129ca6149be45e5 (paper, appendix A).
  CalSecret k;
  uint8_t m[15];
  for (uint8_t i = 0; i < 16; ++i)
    k[i] = i;
  for (uint8_t i = 0; i < 15; ++i)
    m[i] = i;
  CHECK_EQUAL(0xa129ca6149be45e5ull, siphash24(k, m, 15));
  // The key depends on every bit of the seed and of the secret.
  CHECK_TRUE(calibration_key(1, k) != calibration_key(2, k));
  CalSecret k2 = k;
  k2[15] ^= 1;
  CHECK_TRUE(calibration_key(1, k) != calibration_key(1, k2));
}

TEST_GROUP(CalibrationTransfer){};

TEST(CalibrationTransfer, GuardedWriteAppliesTheBlockAndRelocks) {
  Rig rig;
  CHECK_EQUAL(kAccepted, result_of(rig.unlock()));
  CHECK_TRUE(rig.gyro.unlocked());
  const Calibration c = new_calibration();
  const CalibrationBytes b = serialize(c);
  const std::size_t replies_before = rig.replies.size();
  const CalReply end = rig.write(b, calibration_crc(c));
  CHECK_EQUAL(kAccepted, result_of(end));
  CHECK_EQUAL(static_cast<int>(CalStep::end), static_cast<int>(end.step));
  CHECK_EQUAL(calibration_crc(c), end.value);
  CHECK_EQUAL(calibration_crc(c), rig.gyro.active_crc());
  DOUBLES_EQUAL(0.0101, rig.gyro.active().pickoff_y_gain, 0.0);
  CHECK_EQUAL(1u, rig.gyro.applied_count());
  // Accepted data frames are not answered: START and END only.
  CHECK_EQUAL(replies_before + 2, rig.replies.size());
  // One write per unlock.
  CHECK_FALSE(rig.gyro.unlocked());
  rig.send(encode_cal_start(kBlockBytes, calibration_crc(c)));
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  // Bus time of the whole exchange (classic frames, worst-case stuffing).
  auto bits = [](unsigned dlc) {
    const unsigned stuffed = 34 + 8 * dlc;
    return stuffed + (stuffed - 1) / 4 + 13;
  };
  const unsigned total = bits(1) + bits(7) + bits(5) + bits(7) + bits(7) + bits(7) +
                         kDataFrames * bits(8) + bits(1) + bits(7);
  std::printf(
      "\n  guarded write: 4 control + %u data frames + 4 replies, %u bits = %.2f ms at"
      " 1 Mbit/s (event traffic; the cyclic bus load is unchanged)\n",
      kDataFrames, total, total / 1000.0);
}

TEST(CalibrationTransfer, OutsideTheServiceModeEverythingIsRefusedAndAnOpenBlockDropped) {
  Rig rig;
  rig.mode = Mode::operate;
  rig.send(encode_cal_seed_request());
  CHECK_EQUAL(static_cast<int>(CalResult::wrong_state), result_of(rig.last()));
  CHECK_EQUAL(static_cast<int>(Mode::operate), rig.last().detail);
  // A block open when the gyro leaves safe mode is dropped at the next tick.
  rig.mode = Mode::safe;
  rig.unlock();
  const Calibration c = new_calibration();
  const CalibrationBytes b = serialize(c);
  rig.send(encode_cal_start(kBlockBytes, calibration_crc(c)));
  rig.send_data(b, 0, 5);
  CanFrame reply;
  CHECK_TRUE(rig.gyro.tick(rig.now_ms, Mode::ring_up, reply));
  CalReply r;
  CHECK_TRUE(decode_cal_reply(reply, r));
  CHECK_EQUAL(static_cast<int>(CalResult::stale), static_cast<int>(r.result));
  CHECK_EQUAL(35, r.detail);  // bytes received
  rig.send_data(b, 5, kDataFrames);
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  rig.send(encode_cal_end());
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  CHECK_EQUAL(1u, rig.count(CalResult::wrong_state));
  CHECK_EQUAL(1u, rig.count(CalResult::stale));
  rig.expect_unchanged();
}

TEST(CalibrationTransfer, WithoutUnlockNothingOpens) {
  Rig rig;
  const Calibration c = new_calibration();
  rig.send(encode_cal_key(0x12345678));  // no seed asked
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  rig.send(encode_cal_start(kBlockBytes, calibration_crc(c)));
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  const CalibrationBytes b = serialize(c);
  rig.send(encode_cal_data(0, b.data(), 7));
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  rig.send(encode_cal_end());
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  CHECK_EQUAL(4u, rig.count(CalResult::locked));
  // An unlock not used within unlock_timeout_ms lapses.
  rig.unlock();
  rig.now_ms += config().unlock_timeout_ms + 1;
  rig.send(encode_cal_start(kBlockBytes, calibration_crc(c)));
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  rig.expect_unchanged();
}

TEST(CalibrationTransfer, WrongKeysCountDownToALockoutThatEnds) {
  Rig rig;
  CalSecret wrong = config().secret;
  wrong[0] ^= 0x55;
  CalReply r = rig.unlock(wrong);
  CHECK_EQUAL(static_cast<int>(CalResult::bad_key), result_of(r));
  CHECK_EQUAL(2, r.detail);
  // A seed is good for one attempt: the right key for the used seed is refused.
  rig.send(encode_cal_key(0));
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  r = rig.unlock(wrong);
  CHECK_EQUAL(1, r.detail);
  r = rig.unlock(wrong);
  CHECK_EQUAL(static_cast<int>(CalResult::bad_key), result_of(r));
  CHECK_EQUAL(0, r.detail);
  // Locked out: no seed, whatever the key, for lockout_ms.
  rig.now_ms += 2500;
  rig.send(encode_cal_seed_request());
  CHECK_EQUAL(static_cast<int>(CalResult::locked_out), result_of(rig.last()));
  CHECK_EQUAL(8, rig.last().detail);  // 7.5 s left, rounded up
  rig.send(encode_cal_key(0));
  CHECK_EQUAL(static_cast<int>(CalResult::locked_out), result_of(rig.last()));
  CHECK_EQUAL(3u, rig.count(CalResult::bad_key));
  CHECK_EQUAL(2u, rig.count(CalResult::locked_out));
  rig.expect_unchanged();
  // After the lockout the right key unlocks, with the attempts restored.
  rig.now_ms += config().lockout_ms;
  r = rig.unlock();
  CHECK_EQUAL(kAccepted, result_of(r));
  CHECK_EQUAL(3, r.detail);
}

TEST(CalibrationTransfer, CorruptOrMisshapenFramesAreRefused) {
  Rig rig;
  CanFrame seed = encode_cal_seed_request();
  seed.data[0] ^= 1;
  rig.send(seed);
  CHECK_EQUAL(static_cast<int>(CalResult::bad_checksum), result_of(rig.last()));
  CanFrame short_key = encode_cal_key(1);
  short_key.len = 4;
  rig.send(short_key);
  CHECK_EQUAL(static_cast<int>(CalResult::bad_length), result_of(rig.last()));
  CHECK_EQUAL(4, rig.last().detail);
  rig.unlock();
  const Calibration c = new_calibration();
  rig.send(encode_cal_start(104, calibration_crc(c)));  // not the canonical length
  CHECK_EQUAL(static_cast<int>(CalResult::bad_length), result_of(rig.last()));
  // A frame outside the range is not ours.
  CanFrame other = encode_cal_end();
  other.id = 0x0A5;
  CHECK_FALSE(rig.gyro.process(other, Mode::safe, rig.now_ms, 0).for_us);
  CHECK_EQUAL(1u, rig.count(CalResult::bad_checksum));
  CHECK_EQUAL(2u, rig.count(CalResult::bad_length));
  rig.expect_unchanged();
}

TEST(CalibrationTransfer, PartialOutOfOrderOrStaleBlocksChangeNothing) {
  const Calibration c = new_calibration();
  const CalibrationBytes b = serialize(c);
  const uint32_t crc = calibration_crc(c);
  Rig rig;
  // A gap in the sequence drops the block.
  rig.unlock();
  rig.send(encode_cal_start(kBlockBytes, crc));
  rig.send_data(b, 0, 3);
  rig.send(encode_cal_data(4, b.data() + 28, 7));
  CHECK_EQUAL(static_cast<int>(CalResult::bad_sequence), result_of(rig.last()));
  CHECK_EQUAL(3, rig.last().detail);
  rig.send(encode_cal_end());
  CHECK_EQUAL(static_cast<int>(CalResult::locked), result_of(rig.last()));
  // END before the last frame.
  rig.unlock();
  rig.send(encode_cal_start(kBlockBytes, crc));
  rig.send_data(b, 0, kDataFrames - 1);
  rig.send(encode_cal_end());
  CHECK_EQUAL(static_cast<int>(CalResult::incomplete), result_of(rig.last()));
  CHECK_EQUAL(static_cast<int>(kCalDataBytesPerFrame * (kDataFrames - 1)), rig.last().detail);
  // A frame after frame_timeout_ms: the block is stale.
  rig.unlock();
  rig.send(encode_cal_start(kBlockBytes, crc));
  rig.send_data(b, 0, 10);
  rig.now_ms += config().frame_timeout_ms + 1;
  rig.send_data(b, 10, kDataFrames);
  CHECK_EQUAL(static_cast<int>(CalResult::stale), result_of(rig.last()));
  // The same silence noticed by the tick.
  rig.unlock();
  rig.send(encode_cal_start(kBlockBytes, crc));
  rig.send_data(b, 0, 10);
  CanFrame reply;
  const uint32_t last_frame_ms = rig.now_ms - 1;
  CHECK_FALSE(rig.gyro.tick(last_frame_ms + config().frame_timeout_ms, Mode::safe, reply));
  CHECK_TRUE(rig.gyro.tick(last_frame_ms + config().frame_timeout_ms + 1, Mode::safe, reply));
  CHECK_EQUAL(1u, rig.count(CalResult::bad_sequence));
  CHECK_EQUAL(1u, rig.count(CalResult::incomplete));
  CHECK_EQUAL(2u, rig.count(CalResult::stale));
  rig.expect_unchanged();
}

TEST(CalibrationTransfer, CrcFormatAndRangeAreCheckedBeforeAnythingIsApplied) {
  Rig rig;
  const Calibration c = new_calibration();
  CalibrationBytes b = serialize(c);
  // The block's CRC differs from START's (one bit flipped on the way).
  rig.unlock();
  const uint32_t crc = calibration_crc(c);
  b[20] ^= 0x10;
  CHECK_EQUAL(static_cast<int>(CalResult::crc_mismatch), result_of(rig.write(b, crc)));
  // A consistent block of an unknown format version.
  b = serialize(c);
  b[0] = 2;
  rig.unlock();
  CHECK_EQUAL(static_cast<int>(CalResult::bad_format),
              result_of(rig.write(b, crc32(b.data(), b.size()))));
  // A consistent block with one field outside its range: named by index.
  Calibration bad = c;
  bad.duffing_hz_per_v2 = 5.0;  // range +-1 Hz/V^2, field 10
  b = serialize(bad);
  rig.unlock();
  const CalReply r = rig.write(b, calibration_crc(bad));
  CHECK_EQUAL(static_cast<int>(CalResult::out_of_range), result_of(r));
  CHECK_EQUAL(10, r.detail);
  CHECK_EQUAL(1u, rig.count(CalResult::crc_mismatch));
  CHECK_EQUAL(1u, rig.count(CalResult::bad_format));
  CHECK_EQUAL(1u, rig.count(CalResult::out_of_range));
  rig.expect_unchanged();
  // And after all that, a good block still goes through.
  rig.unlock();
  CHECK_EQUAL(kAccepted, result_of(rig.write(serialize(c), crc)));
  CHECK_EQUAL(crc, rig.gyro.active_crc());
}

TEST(CalibrationTransfer, ABlockTheFirmwareCannotPutInForceIsRefusedAndChangesNothing) {
  // The apply hook is the firmware's one apply path: when it refuses (the
  // chain's formats cannot hold the correction) the transfer does too.
  Rig rig;
  int calls = 0;
  struct Ctx {
    int* calls;
    bool accept;
  } ctx{&calls, false};
  rig.gyro.set_apply(
      [](void* p, const Calibration&) {
        auto* c = static_cast<Ctx*>(p);
        ++*c->calls;
        return c->accept;
      },
      &ctx);
  const Calibration c = new_calibration();
  rig.unlock();
  const CalReply r = rig.write(serialize(c), calibration_crc(c));
  CHECK_EQUAL(static_cast<int>(CalResult::not_applied), result_of(r));
  CHECK_EQUAL(calibration_crc(kIdentityCalibration), r.value);  // still the one in force
  CHECK_EQUAL(1, calls);
  rig.expect_unchanged();
  ctx.accept = true;
  rig.unlock();
  CHECK_EQUAL(kAccepted, result_of(rig.write(serialize(c), calibration_crc(c))));
  CHECK_EQUAL(2, calls);
  CHECK_EQUAL(calibration_crc(c), rig.gyro.active_crc());
}
