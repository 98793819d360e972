// SPDX-License-Identifier: MIT
// The converter seam on Linux: a driver's interleaved sample stream (IIO
// buffer layout) becomes Q1.31 blocks and back, at the rails of every format,
// through a pipe standing in for /dev/iio:deviceN.
#include <unistd.h>

#include <array>
#include <cstdint>
#include <vector>

#include "hal/linux/linux_clock.hpp"
#include "hal/linux/stream_converters.hpp"

#include "support/cpputest.hpp"

using namespace hrg::hal;
using namespace hrg::hal::linux_board;

namespace {

StreamConfig config(SampleFormat f, uint32_t frames = 4) {
  StreamConfig c;
  c.info = {100'000, frames, 2.5};
  c.format = f;
  return c;
}

}  // namespace

TEST_GROUP(SampleCodec){};

TEST(SampleCodec, SignedSixteenBitLittleEndianIsLeftJustified) {
  const SampleFormat f{16, 2, 0, true, false};
  bool clipped = false;
  const uint8_t minus_one[] = {0xFF, 0xFF};
  LONGS_EQUAL(-65536, decode_sample(minus_one, f, clipped));  // -1 LSB = -2^16 in Q1.31
  CHECK_FALSE(clipped);
  const uint8_t max[] = {0xFF, 0x7F};
  LONGS_EQUAL(0x7FFF0000, decode_sample(max, f, clipped));
  CHECK(clipped);
  const uint8_t min[] = {0x00, 0x80};
  LONGS_EQUAL(INT32_MIN, decode_sample(min, f, clipped));
  CHECK(clipped);
}

TEST(SampleCodec, OffsetBinaryTwelveBitsBigEndianShiftedByFour) {
  // IIO "be:u12/16>>4": mid-scale 0x800 is 0 V.
  const SampleFormat f{12, 2, 4, false, true};
  bool clipped = true;
  const uint8_t mid[] = {0x80, 0x00};
  LONGS_EQUAL(0, decode_sample(mid, f, clipped));
  CHECK_FALSE(clipped);
  const uint8_t top[] = {0xFF, 0xF0};  // code 0xFFF: +full scale less one LSB
  LONGS_EQUAL(0x7FF00000, decode_sample(top, f, clipped));
  CHECK(clipped);
  const uint8_t bottom[] = {0x00, 0x00};
  LONGS_EQUAL(INT32_MIN, decode_sample(bottom, f, clipped));
  CHECK(clipped);
  // And back: the DAC keeps the top 12 bits.
  uint8_t out[2];
  encode_sample(0x7FF00000 + 0xFFFFF, f, out);  // low bits below one LSB are dropped
  LONGS_EQUAL(0xFF, out[0]);
  LONGS_EQUAL(0xF0, out[1]);
}

TEST(SampleCodec, EveryCodeOfEveryFormatRoundTrips) {
  const SampleFormat formats[] = {{8, 1, 0, true, false},  {12, 2, 4, false, true},
                                  {16, 2, 0, true, false}, {18, 4, 0, true, false},
                                  {24, 4, 8, false, true}, {32, 4, 0, true, false}};
  for (const auto& f : formats) {
    CHECK(valid(f));
    const uint32_t n = f.bits >= 20 ? 4096u : (1u << f.bits);
    for (uint32_t k = 0; k < n; ++k) {
      // Spread the probes over the whole code range, rails included.
      const uint64_t span = (f.bits == 32 ? 0x100000000ull : (1ull << f.bits)) - 1;
      const uint32_t code = static_cast<uint32_t>(span * k / (n - 1));
      const auto word = static_cast<q31_t>(f.bits == 32 ? code : code << (32 - f.bits));
      uint8_t bytes[4] = {};
      encode_sample(word, f, bytes);
      bool clipped = false;
      LONGS_EQUAL(word, decode_sample(bytes, f, clipped));
    }
  }
  CHECK_FALSE(valid(SampleFormat{16, 2, 4, true, false}));  // 4 + 16 bits do not fit in 16
  CHECK_FALSE(valid(SampleFormat{16, 3, 0, true, false}));
}

TEST_GROUP(StreamConverters) {
  int fds[2] = {-1, -1};
  LinuxClock clock;
  void setup() override { CHECK(::pipe(fds) == 0); }
  void teardown() override {
    if (fds[1] >= 0) ::close(fds[1]);
  }
};

TEST(StreamConverters, AnAdcBlockIsReadInterleavedWithClippedCount) {
  StreamAdc adc;
  CHECK(Status::ok == adc.adopt(fds[0], config({16, 2, 0, true, false}), clock));
  // 4 frames x 2 channels of s16: x = 0, 1000, 32767 (clipped), -32768 (clipped).
  const int16_t codes[8] = {0, -1, 1000, -1000, 32767, 5, -32768, 6};
  CHECK(::write(fds[1], codes, sizeof codes) == static_cast<ssize_t>(sizeof codes));
  std::array<q31_t, 8> block{};
  uint64_t t_first = 0;
  uint32_t clipped = 0;
  const uint64_t before = clock.now_ns();
  CHECK(Status::ok == adc.read_block(block, t_first, clipped));
  for (int i = 0; i < 8; ++i)
    LONGS_EQUAL(codes[i] * 65536, block[i]);
  LONGS_EQUAL(2, clipped);
  // The first frame was sampled one block (40 us) before the block completed.
  CHECK(t_first <= clock.now_ns() - 40'000);
  CHECK(t_first + 40'000 >= before);
}

TEST(StreamConverters, AnIncompleteBlockTimesOutAndCompletesLater) {
  StreamAdc adc;
  CHECK(Status::ok == adc.adopt(fds[0], config({16, 2, 0, true, false}), clock));
  const int16_t first[3] = {1, 2, 3};
  CHECK(::write(fds[1], first, sizeof first) > 0);
  std::array<q31_t, 8> block{};
  uint64_t t = 0;
  uint32_t clipped = 0;
  CHECK(Status::timeout == adc.read_block(block, t, clipped));
  const int16_t rest[5] = {4, 5, 6, 7, 8};
  CHECK(::write(fds[1], rest, sizeof rest) > 0);
  CHECK(Status::ok == adc.read_block(block, t, clipped));
  LONGS_EQUAL(1 * 65536, block[0]);
  LONGS_EQUAL(8 * 65536, block[7]);
  std::array<q31_t, 6> wrong{};
  CHECK(Status::invalid_argument == adc.read_block(wrong, t, clipped));
}

TEST(StreamConverters, TheAdcReportsAClosedStream) {
  StreamAdc adc;
  CHECK(Status::ok == adc.adopt(fds[0], config({16, 2, 0, true, false}), clock));
  ::close(fds[1]);
  fds[1] = -1;
  std::array<q31_t, 8> block{};
  uint64_t t = 0;
  uint32_t clipped = 0;
  CHECK(Status::closed == adc.read_block(block, t, clipped));
}

TEST(StreamConverters, DacBlocksComeOutTruncatedToTheConverterBits) {
  StreamDac dac;
  const int rd = fds[0];
  CHECK(Status::ok == dac.adopt(fds[1], config({12, 2, 4, false, true}, 2)));
  fds[1] = -1;  // owned by the DAC now
  // pump, fx, fy for 2 frames.
  const std::array<q31_t, 6> words = {0, INT32_MAX, INT32_MIN, 0x00100000 - 1, -1, 0x40000000};
  CHECK(Status::ok == dac.write_block(words));
  uint8_t out[12];
  CHECK(::read(rd, out, sizeof out) == 12);
  const uint16_t expect[6] = {0x8000, 0xFFF0, 0x0000, 0x8000, 0x7FF0, 0xC000};
  for (int i = 0; i < 6; ++i)
    LONGS_EQUAL(expect[i], (out[2 * i] << 8) | out[2 * i + 1]);
  ::close(rd);
}

TEST(StreamConverters, AFullDriverBufferRefusesTheBlockWithoutBlocking) {
  StreamDac dac;
  const int rd = fds[0];
  CHECK(Status::ok == dac.adopt(fds[1], config({16, 2, 0, true, false}, 1000)));
  fds[1] = -1;
  std::vector<q31_t> block(3000, 0x12345678);
  // A pipe holds 64 KiB: 6000-byte blocks fill it after 10.
  int ok = 0;
  int refused = 0;
  for (int i = 0; i < 30; ++i) {
    const Status s = dac.write_block(block);
    ok += s == Status::ok ? 1 : 0;
    refused += s == Status::would_block ? 1 : 0;
  }
  CHECK(ok >= 10 && ok <= 11);
  LONGS_EQUAL(30, ok + refused);
  LONGS_EQUAL(refused, dac.refused_blocks());
  ::close(rd);
}
