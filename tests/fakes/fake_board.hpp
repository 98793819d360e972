// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "fakes/fake_clock.hpp"
#include "firmware/mode.hpp"
#include "fakes/fake_can.hpp"
#include "hal/board.hpp"

namespace hrg::fakes {

// ADC that produces a block per call and moves the (lockstep) clock by one
// block. Back door: the sample pattern, a stuck channel, clipped counts,
// a failing status and skipped blocks.
class FakeAdc final : public hal::Adc {
 public:
  explicit FakeAdc(FakeClock& clock) : clock_(clock) {}
  hal::ConverterInfo info() const override { return {rate_hz_, block_frames_, 2.5}; }
  hal::Status read_block(std::span<hal::q31_t> frames, uint64_t& t_first_ns,
                         uint32_t& clipped) override {
    ++reads_;
    if (status_ != hal::Status::ok) return status_;
    t_first_ns = clock_.now_ns() + skip_blocks_ * block_ns();
    clock_.set_now_ns(t_first_ns + block_ns());
    skip_blocks_ = 0;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      frames[i] = static_cast<hal::q31_t>((counter_++ % 1000) * 1000);
      if (stuck_ && i % hal::kAdcChannels == 1) frames[i] = 12345;
    }
    clipped = clipped_;
    return hal::Status::ok;
  }

  uint64_t block_ns() const { return 1'000'000'000ull * block_frames_ / rate_hz_; }
  void set_stuck(bool on) { stuck_ = on; }
  void set_clipped(uint32_t n) { clipped_ = n; }
  void set_status(hal::Status s) { status_ = s; }
  void skip_blocks(uint32_t n) { skip_blocks_ = n; }
  void set_layout(uint32_t rate_hz, uint32_t block_frames) {
    rate_hz_ = rate_hz;
    block_frames_ = block_frames;
  }
  uint32_t reads() const { return reads_; }

 private:
  FakeClock& clock_;
  uint32_t rate_hz_ = fw::kAdcRateHz;
  uint32_t block_frames_ = fw::kBlockFrames;
  uint32_t counter_ = 0;
  uint32_t clipped_ = 0;
  uint32_t skip_blocks_ = 0;
  uint32_t reads_ = 0;
  bool stuck_ = false;
  hal::Status status_ = hal::Status::ok;
};

// DAC that keeps the last block written. Back door: a failing status.
class FakeDac final : public hal::Dac {
 public:
  hal::ConverterInfo info() const override { return {fw::kAdcRateHz, fw::kBlockFrames, 10.0}; }
  hal::Status write_block(std::span<const hal::q31_t> frames) override {
    ++writes_;
    for (std::size_t i = 0; i < frames.size() && i < last_.size(); ++i)
      last_[i] = frames[i];
    return status_;
  }
  // True when any frame of the last block drives `channel`.
  bool driving(std::size_t channel) const {
    for (std::size_t i = channel; i < last_.size(); i += hal::kDacChannels) {
      if (last_[i] != 0) return true;
    }
    return false;
  }
  void set_status(hal::Status s) { status_ = s; }
  uint32_t writes() const { return writes_; }

 private:
  std::array<hal::q31_t, fw::kBlockFrames * hal::kDacChannels> last_{};
  hal::Status status_ = hal::Status::ok;
  uint32_t writes_ = 0;
};

class FakeDigitalOut final : public hal::DigitalOut {
 public:
  hal::Status write(bool active) override {
    level_ = active;
    ++writes_;
    return hal::Status::ok;
  }
  bool level() const { return level_; }
  uint32_t writes() const { return writes_; }

 private:
  bool level_ = false;
  uint32_t writes_ = 0;
};

class FakeDigitalIn final : public hal::DigitalIn {
 public:
  hal::Status read(bool& active) override {
    active = level_;
    return hal::Status::ok;
  }
  void set_level(bool on) { level_ = on; }

 private:
  bool level_ = false;
};

// A temperature input whose reading and status the test sets (closed by
// default: a board without a sensor).
class FakeTemperature final : public hal::TemperatureSensor {
 public:
  hal::Status read(double& temp_c) override {
    ++reads_;
    if (status_ == hal::Status::ok) temp_c = temp_c_;
    return status_;
  }
  void set(double temp_c, hal::Status st = hal::Status::ok) {
    temp_c_ = temp_c;
    status_ = st;
  }
  uint32_t reads() const { return reads_; }

 private:
  double temp_c_ = 0.0;
  hal::Status status_ = hal::Status::closed;
  uint32_t reads_ = 0;
};

// A whole board on the fakes, in lockstep.
struct FakeBoard {
  FakeClock clock;
  FakeAdc adc{clock};
  FakeDac dac;
  FakeDigitalOut enable;
  FakeDigitalIn fault_in;
  FakeCan can;
  FakeTemperature temperature;
  hal::Board board{adc, dac, enable, fault_in, can, clock, temperature};
  FakeBoard() { clock.set_lockstep(true); }
};

}  // namespace hrg::fakes
