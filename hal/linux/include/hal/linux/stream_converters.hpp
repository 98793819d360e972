// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hal/clock.hpp"
#include "hal/converters.hpp"

namespace hrg::hal::linux_board {

// The converter seam on Linux. The firmware sees hal::Adc / hal::Dac blocks;
// behind them a kernel driver streams interleaved samples through a character
// device: an IIO buffer (/dev/iio:deviceN with the channels' scan elements
// enabled), a vendor driver with the same byte layout, or a pipe in tests.
// The layout is IIO's scan element type ("le:s16/16>>0", "be:u12/16>>4"):
struct SampleFormat {
  uint8_t bits = 16;          // significant bits (the converter's resolution)
  uint8_t storage_bytes = 2;  // 1, 2 or 4 bytes per sample in the stream
  uint8_t shift = 0;          // right shift from the storage word to the code
  bool is_signed = true;      // two's complement; false: offset binary (mid-scale = 0 V)
  bool big_endian = false;
};

struct StreamConfig {
  ConverterInfo info{};  // rate, frames per block, volts at Q1.31 full scale
  SampleFormat format{};
};

// ADC over a stream. Samples are left-justified into Q1.31 (code << (32 -
// bits)), so the firmware never depends on the resolution; a code at either
// end of its range counts as clipped.
class StreamAdc final : public Adc {
 public:
  StreamAdc() = default;
  ~StreamAdc() override;

  // Opens `path` read-only, non-blocking. invalid_argument for a bad format or
  // a missing device, io_error otherwise. Allocates the block buffer here.
  Status open(const char* path, const StreamConfig& config, MonotonicClock& clock);
  // Same on an already open descriptor (taken over; closed with the object).
  Status adopt(int fd, const StreamConfig& config, MonotonicClock& clock);
  void close();

  ConverterInfo info() const override { return config_.info; }
  // Waits up to two block periods for the rest of the block; timeout when it
  // is still incomplete (the part read is kept for the next call). The first
  // frame's time is the completion time less one block duration.
  Status read_block(std::span<q31_t> frames, uint64_t& t_first_ns, uint32_t& clipped) override;

 private:
  int fd_ = -1;
  StreamConfig config_{};
  MonotonicClock* clock_ = nullptr;
  std::vector<uint8_t> buf_;
  std::size_t filled_ = 0;
};

// DAC over a stream: Q1.31 words are truncated to the converter's bits (as a
// DAC ignores the low bits) and written in the stream's format.
class StreamDac final : public Dac {
 public:
  StreamDac() = default;
  ~StreamDac() override;

  // Opens `path` write-only, non-blocking.
  Status open(const char* path, const StreamConfig& config);
  Status adopt(int fd, const StreamConfig& config);
  void close();

  ConverterInfo info() const override { return config_.info; }
  // Queues one block. would_block when the driver's buffer cannot take it
  // (nothing of this block is written then, unless a previous block's tail is
  // still pending, which goes first).
  Status write_block(std::span<const q31_t> frames) override;
  uint32_t refused_blocks() const { return refused_; }

 private:
  Status flush_pending();
  int fd_ = -1;
  StreamConfig config_{};
  std::vector<uint8_t> buf_;
  std::size_t pending_from_ = 0;  // bytes [pending_from_, pending_to_) still to write
  std::size_t pending_to_ = 0;
  uint32_t refused_ = 0;
};

// Codec of one sample (exposed for tests): storage bytes <-> Q1.31.
q31_t decode_sample(const uint8_t* p, const SampleFormat& f, bool& clipped);
void encode_sample(q31_t word, const SampleFormat& f, uint8_t* p);
bool valid(const SampleFormat& f);
// Parses an IIO scan element type ("le:s16/16>>0", "be:u12/16>>4"; a repeat
// count "X2" is not supported). Returns false for anything else.
bool parse_iio_type(const char* text, SampleFormat& out);

}  // namespace hrg::hal::linux_board
