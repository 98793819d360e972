// SPDX-License-Identifier: MIT
#include "hal/linux/stream_converters.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace hrg::hal::linux_board {

namespace {

uint32_t load(const uint8_t* p, const SampleFormat& f) {
  uint32_t w = 0;
  for (unsigned i = 0; i < f.storage_bytes; ++i) {
    const unsigned byte = f.big_endian ? i : f.storage_bytes - 1u - i;
    w = (w << 8) | p[byte];
  }
  return w;
}

void store(uint32_t w, const SampleFormat& f, uint8_t* p) {
  for (unsigned i = 0; i < f.storage_bytes; ++i) {
    const unsigned byte = f.big_endian ? f.storage_bytes - 1u - i : i;
    p[byte] = static_cast<uint8_t>(w >> (8 * i));
  }
}

std::size_t block_bytes(const StreamConfig& c, std::size_t channels) {
  return static_cast<std::size_t>(c.info.block_frames) * channels * c.format.storage_bytes;
}

bool read_uint(const char*& p, unsigned& out) {
  if (*p < '0' || *p > '9') return false;
  unsigned v = 0;
  while (*p >= '0' && *p <= '9' && v < 1000)
    v = v * 10 + static_cast<unsigned>(*p++ - '0');
  out = v;
  return true;
}

}  // namespace

bool parse_iio_type(const char* text, SampleFormat& out) {
  if (text == nullptr) return false;
  SampleFormat f;
  const char* p = text;
  if (std::strncmp(p, "le:", 3) == 0) {
    f.big_endian = false;
  } else if (std::strncmp(p, "be:", 3) == 0) {
    f.big_endian = true;
  } else {
    return false;
  }
  p += 3;
  if (*p != 's' && *p != 'u') return false;
  f.is_signed = *p++ == 's';
  unsigned bits = 0;
  unsigned storage = 0;
  unsigned shift = 0;
  if (!read_uint(p, bits) || *p++ != '/' || !read_uint(p, storage)) return false;
  if (std::strncmp(p, ">>", 2) != 0) return false;
  p += 2;
  if (!read_uint(p, shift) || *p != '\0') return false;
  if (storage % 8 != 0 || bits > 32 || storage > 32 || shift > 32) return false;
  f.bits = static_cast<uint8_t>(bits);
  f.storage_bytes = static_cast<uint8_t>(storage / 8);
  f.shift = static_cast<uint8_t>(shift);
  if (!valid(f)) return false;
  out = f;
  return true;
}

bool valid(const SampleFormat& f) {
  const bool storage_ok = f.storage_bytes == 1 || f.storage_bytes == 2 || f.storage_bytes == 4;
  return storage_ok && f.bits >= 2 && f.bits <= 32 && f.shift + f.bits <= 8 * f.storage_bytes;
}

q31_t decode_sample(const uint8_t* p, const SampleFormat& f, bool& clipped) {
  const uint32_t mask = f.bits == 32 ? 0xFFFFFFFFu : (1u << f.bits) - 1u;
  uint32_t code = (load(p, f) >> f.shift) & mask;
  // Offset binary: flipping the top bit turns it into two's complement.
  if (!f.is_signed) code ^= 1u << (f.bits - 1);
  const uint32_t top = 1u << (f.bits - 1);
  clipped = code == top || code == top - 1u;  // most negative / most positive code
  // Left-justify: Q1.31 full scale whatever the resolution.
  return static_cast<q31_t>(code << (32 - f.bits));
}

void encode_sample(q31_t word, const SampleFormat& f, uint8_t* p) {
  const uint32_t mask = f.bits == 32 ? 0xFFFFFFFFu : (1u << f.bits) - 1u;
  uint32_t code = (static_cast<uint32_t>(word) >> (32 - f.bits)) & mask;  // truncates
  if (!f.is_signed) code ^= 1u << (f.bits - 1);
  store(code << f.shift, f, p);
}

StreamAdc::~StreamAdc() { close(); }

void StreamAdc::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Status StreamAdc::open(const char* path, const StreamConfig& config, MonotonicClock& clock) {
  const int fd = ::open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return errno == ENOENT ? Status::invalid_argument : Status::io_error;
  return adopt(fd, config, clock);
}

Status StreamAdc::adopt(int fd, const StreamConfig& config, MonotonicClock& clock) {
  close();
  if (!valid(config.format) || config.info.block_frames == 0 || config.info.sample_rate_hz == 0) {
    ::close(fd);
    return Status::invalid_argument;
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
  fd_ = fd;
  config_ = config;
  clock_ = &clock;
  buf_.assign(block_bytes(config, kAdcChannels), 0);
  filled_ = 0;
  return Status::ok;
}

Status StreamAdc::read_block(std::span<q31_t> frames, uint64_t& t_first_ns, uint32_t& clipped) {
  if (fd_ < 0) return Status::closed;
  if (frames.size() != static_cast<std::size_t>(config_.info.block_frames) * kAdcChannels) {
    return Status::invalid_argument;
  }
  const uint64_t block_ns =
      1'000'000'000ull * config_.info.block_frames / config_.info.sample_rate_hz;
  const uint64_t deadline = clock_->now_ns() + 2 * block_ns;
  while (filled_ < buf_.size()) {
    const ssize_t n = ::read(fd_, buf_.data() + filled_, buf_.size() - filled_);
    if (n > 0) {
      filled_ += static_cast<std::size_t>(n);
      continue;
    }
    if (n == 0) return Status::closed;  // the writer went away
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) return Status::io_error;
    const uint64_t now = clock_->now_ns();
    if (now >= deadline) return Status::timeout;
    pollfd p{fd_, POLLIN, 0};
    const int wait_ms = static_cast<int>((deadline - now + 999'999) / 1'000'000);
    if (::poll(&p, 1, wait_ms) < 0 && errno != EINTR) return Status::io_error;
  }
  const uint64_t done_ns = clock_->now_ns();
  t_first_ns = done_ns > block_ns ? done_ns - block_ns : 0;
  clipped = 0;
  const std::size_t step = config_.format.storage_bytes;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    bool c = false;
    frames[i] = decode_sample(buf_.data() + i * step, config_.format, c);
    clipped += c ? 1u : 0u;
  }
  filled_ = 0;
  return Status::ok;
}

StreamDac::~StreamDac() { close(); }

void StreamDac::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Status StreamDac::open(const char* path, const StreamConfig& config) {
  const int fd = ::open(path, O_WRONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return errno == ENOENT ? Status::invalid_argument : Status::io_error;
  return adopt(fd, config);
}

Status StreamDac::adopt(int fd, const StreamConfig& config) {
  close();
  if (!valid(config.format) || config.info.block_frames == 0) {
    ::close(fd);
    return Status::invalid_argument;
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
  fd_ = fd;
  config_ = config;
  buf_.assign(block_bytes(config, kDacChannels), 0);
  pending_from_ = pending_to_ = 0;
  return Status::ok;
}

Status StreamDac::flush_pending() {
  while (pending_from_ < pending_to_) {
    const ssize_t n = ::write(fd_, buf_.data() + pending_from_, pending_to_ - pending_from_);
    if (n > 0) {
      pending_from_ += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return Status::would_block;
    return Status::io_error;
  }
  return Status::ok;
}

Status StreamDac::write_block(std::span<const q31_t> frames) {
  if (fd_ < 0) return Status::closed;
  if (frames.size() != static_cast<std::size_t>(config_.info.block_frames) * kDacChannels) {
    return Status::invalid_argument;
  }
  // A previous block's tail goes out first; until it has, this block is refused
  // (the buffer still holds that tail).
  const Status s = flush_pending();
  if (s != Status::ok) {
    ++refused_;
    return s;
  }
  const std::size_t step = config_.format.storage_bytes;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    encode_sample(frames[i], config_.format, buf_.data() + i * step);
  }
  pending_from_ = 0;
  pending_to_ = buf_.size();
  const Status w = flush_pending();
  if (w == Status::would_block && pending_from_ == 0) {
    // Nothing of this block went out: refuse it whole.
    pending_to_ = 0;
    ++refused_;
    return Status::would_block;
  }
  // Partly written: the tail is sent before the next block.
  return w == Status::would_block ? Status::ok : w;
}

}  // namespace hrg::hal::linux_board
