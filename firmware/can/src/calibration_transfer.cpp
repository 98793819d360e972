// SPDX-License-Identifier: MIT
#include "firmware/can/calibration_transfer.hpp"

#include "firmware/can/command.hpp"
#include "firmware/can/messages.hpp"

namespace hrg::fw::can {

namespace {

constexpr uint8_t kDlc[] = {1, 5, 7, 8, 1};  // seed request, key, start, data, end

uint64_t rotl(uint64_t x, int b) { return (x << b) | (x >> (64 - b)); }

void sip_round(uint64_t& v0, uint64_t& v1, uint64_t& v2, uint64_t& v3) {
  v0 += v1;
  v1 = rotl(v1, 13);
  v1 ^= v0;
  v0 = rotl(v0, 32);
  v2 += v3;
  v3 = rotl(v3, 16);
  v3 ^= v2;
  v0 += v3;
  v3 = rotl(v3, 21);
  v3 ^= v0;
  v2 += v1;
  v1 = rotl(v1, 17);
  v1 ^= v2;
  v2 = rotl(v2, 32);
}

uint64_t le64(const uint8_t* p, std::size_t n) {
  uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i)
    v |= static_cast<uint64_t>(p[i]) << (8 * i);
  return v;
}

hal::CanFrame control_frame(uint32_t id, uint8_t dlc) {
  hal::CanFrame f;
  f.id = id;
  f.len = dlc;
  return f;
}

void seal(hal::CanFrame& f) {
  f.data[f.len - 1] = command_crc8(f.id, f.data.data(), static_cast<uint8_t>(f.len - 1));
}

bool elapsed(uint32_t now_ms, uint32_t since_ms, uint32_t limit_ms) {
  return static_cast<uint32_t>(now_ms - since_ms) > limit_ms;
}

}  // namespace

const char* to_string(CalResult r) {
  static constexpr const char* kNames[kCalResultCount] = {
      "accepted",     "bad_length", "bad_checksum", "wrong_state", "locked",
      "bad_key",      "locked_out", "bad_sequence", "stale",       "crc_mismatch",
      "out_of_range", "bad_format", "incomplete",   "not_applied"};
  const auto i = static_cast<std::size_t>(r);
  return i < kCalResultCount ? kNames[i] : "unknown";
}

uint64_t siphash24(const CalSecret& key, const uint8_t* data, std::size_t n) {
  const uint64_t k0 = le64(key.data(), 8);
  const uint64_t k1 = le64(key.data() + 8, 8);
  uint64_t v0 = k0 ^ 0x736f6d6570736575ull;
  uint64_t v1 = k1 ^ 0x646f72616e646f6dull;
  uint64_t v2 = k0 ^ 0x6c7967656e657261ull;
  uint64_t v3 = k1 ^ 0x7465646279746573ull;
  const std::size_t full = n / 8 * 8;
  for (std::size_t i = 0; i < full; i += 8) {
    const uint64_t m = le64(data + i, 8);
    v3 ^= m;
    sip_round(v0, v1, v2, v3);
    sip_round(v0, v1, v2, v3);
    v0 ^= m;
  }
  const uint64_t last = (static_cast<uint64_t>(n & 0xFFu) << 56) | le64(data + full, n - full);
  v3 ^= last;
  sip_round(v0, v1, v2, v3);
  sip_round(v0, v1, v2, v3);
  v0 ^= last;
  v2 ^= 0xFF;
  for (int i = 0; i < 4; ++i)
    sip_round(v0, v1, v2, v3);
  return v0 ^ v1 ^ v2 ^ v3;
}

uint32_t calibration_key(uint32_t seed, const CalSecret& secret) {
  const uint8_t b[4] = {static_cast<uint8_t>(seed), static_cast<uint8_t>(seed >> 8),
                        static_cast<uint8_t>(seed >> 16), static_cast<uint8_t>(seed >> 24)};
  return static_cast<uint32_t>(siphash24(secret, b, 4));
}

CalibrationTransfer::CalibrationTransfer(const CalTransferConfig& cfg, const Calibration& active)
    : cfg_(cfg),
      active_(active),
      active_crc_(calibration_crc(active)),
      attempts_left_(cfg.max_attempts) {}

void CalibrationTransfer::set_active(const Calibration& active) {
  active_ = active;
  active_crc_ = calibration_crc(active);
}

CalTransferOutcome CalibrationTransfer::answer(CalStep step, CalResult r, uint8_t detail,
                                               uint32_t value) {
  CalTransferOutcome o;
  o.for_us = true;
  o.reply_ready = true;
  o.result = r;
  o.detail = detail;
  o.reply = control_frame(kCalReplyId, 7);
  put_bits(o.reply, 0, 4, static_cast<uint8_t>(step));
  put_bits(o.reply, 4, 4, static_cast<uint8_t>(r));
  put_bits(o.reply, 8, 8, detail);
  put_bits(o.reply, 16, 32, value);
  put_bits(o.reply, 48, 8, reply_seq_++);
  ++counts_[static_cast<std::size_t>(r)];
  return o;
}

void CalibrationTransfer::drop_block() {
  state_ = State::idle;
  received_ = 0;
  next_seq_ = 0;
  block_ = {};
}

bool CalibrationTransfer::locked_out(uint32_t now_ms) const {
  return lockout_ && !elapsed(now_ms, lockout_start_ms_, cfg_.lockout_ms);
}

CalTransferOutcome CalibrationTransfer::process(const hal::CanFrame& f, Mode mode, uint32_t now_ms,
                                                uint32_t entropy) {
  if (f.extended || !is_calibration_id(f.id)) return {};
  const auto step = static_cast<CalStep>(f.id - kCalSeedRequestId);
  const uint8_t dlc = kDlc[static_cast<std::size_t>(step)];
  // Outside the service mode nothing is unlocked and no block stays open.
  if (mode != Mode::safe) {
    drop_block();
    return answer(step, CalResult::wrong_state, static_cast<uint8_t>(mode));
  }
  if (lockout_ && !locked_out(now_ms)) {
    lockout_ = false;
    attempts_left_ = cfg_.max_attempts;
  }
  const bool in_block = state_ == State::receiving;
  if (f.len != dlc) {
    if (in_block) drop_block();
    return answer(step, CalResult::bad_length, f.len);
  }
  if (step != CalStep::data &&
      command_crc8(f.id, f.data.data(), static_cast<uint8_t>(f.len - 1)) != f.data[f.len - 1]) {
    if (in_block) drop_block();
    return answer(step, CalResult::bad_checksum, 0);
  }
  // An unlock lapses when unused.
  if ((state_ == State::seed_sent || state_ == State::unlocked) &&
      elapsed(now_ms, last_activity_ms_, cfg_.unlock_timeout_ms)) {
    state_ = State::idle;
  }
  switch (step) {
    case CalStep::seed: return on_seed_request(now_ms, entropy);
    case CalStep::key: return on_key(f, now_ms);
    case CalStep::start: return on_start(f, now_ms);
    case CalStep::data: return on_data(f, now_ms);
    default: return on_end(now_ms);
  }
}

CalTransferOutcome CalibrationTransfer::on_seed_request(uint32_t now_ms, uint32_t entropy) {
  if (locked_out(now_ms)) {
    const uint32_t left = cfg_.lockout_ms - static_cast<uint32_t>(now_ms - lockout_start_ms_);
    const uint32_t s = (left + 999u) / 1000u;
    return answer(CalStep::seed, CalResult::locked_out, static_cast<uint8_t>(s > 255 ? 255 : s));
  }
  drop_block();
  // The caller's entropy, whitened with the secret and a request count, so
  // that a weak source does not repeat seeds; never 0.
  const uint8_t b[8] = {static_cast<uint8_t>(entropy),       static_cast<uint8_t>(entropy >> 8),
                        static_cast<uint8_t>(entropy >> 16), static_cast<uint8_t>(entropy >> 24),
                        static_cast<uint8_t>(reply_seq_),    static_cast<uint8_t>(applied_),
                        static_cast<uint8_t>(now_ms),        static_cast<uint8_t>(now_ms >> 8)};
  seed_ = static_cast<uint32_t>(siphash24(cfg_.secret, b, 8) >> 32);
  if (seed_ == 0) seed_ = 1;
  state_ = State::seed_sent;
  last_activity_ms_ = now_ms;
  return answer(CalStep::seed, CalResult::accepted, attempts_left_, seed_);
}

CalTransferOutcome CalibrationTransfer::on_key(const hal::CanFrame& f, uint32_t now_ms) {
  if (locked_out(now_ms)) return answer(CalStep::key, CalResult::locked_out, 0);
  if (state_ != State::seed_sent) return answer(CalStep::key, CalResult::locked, 0);
  const auto key = static_cast<uint32_t>(get_bits(f, 0, 32));
  const bool good = key == calibration_key(seed_, cfg_.secret);
  seed_ = 0;  // one attempt per seed
  last_activity_ms_ = now_ms;
  if (good) {
    state_ = State::unlocked;
    attempts_left_ = cfg_.max_attempts;
    return answer(CalStep::key, CalResult::accepted, attempts_left_);
  }
  state_ = State::idle;
  if (attempts_left_ > 0) --attempts_left_;
  if (attempts_left_ == 0) {
    lockout_ = true;
    lockout_start_ms_ = now_ms;
  }
  return answer(CalStep::key, CalResult::bad_key, attempts_left_);
}

CalTransferOutcome CalibrationTransfer::on_start(const hal::CanFrame& f, uint32_t now_ms) {
  if (state_ != State::unlocked && state_ != State::receiving) {
    return answer(CalStep::start, CalResult::locked, 0);
  }
  const auto length = static_cast<uint16_t>(get_bits(f, 0, 16));
  if (length != kCalibrationBytes) {
    drop_block();
    return answer(CalStep::start, CalResult::bad_length, static_cast<uint8_t>(length & 0xFFu));
  }
  drop_block();
  state_ = State::receiving;
  block_crc_ = static_cast<uint32_t>(get_bits(f, 16, 32));
  last_activity_ms_ = now_ms;
  return answer(CalStep::start, CalResult::accepted, 0);
}

CalTransferOutcome CalibrationTransfer::on_data(const hal::CanFrame& f, uint32_t now_ms) {
  if (state_ != State::receiving) return answer(CalStep::data, CalResult::locked, 0);
  if (elapsed(now_ms, last_activity_ms_, cfg_.frame_timeout_ms)) {
    const auto got = static_cast<uint8_t>(received_);
    drop_block();
    return answer(CalStep::data, CalResult::stale, got);
  }
  const uint8_t seq = f.data[0];
  if (seq != next_seq_ || received_ >= kCalibrationBytes) {
    const uint8_t expected = next_seq_;
    drop_block();
    return answer(CalStep::data, CalResult::bad_sequence, expected);
  }
  for (unsigned i = 0; i < kCalDataBytesPerFrame && received_ < kCalibrationBytes; ++i) {
    block_[received_++] = f.data[1 + i];
  }
  ++next_seq_;
  last_activity_ms_ = now_ms;
  ++counts_[static_cast<std::size_t>(CalResult::accepted)];
  CalTransferOutcome o;
  o.for_us = true;
  return o;
}

CalTransferOutcome CalibrationTransfer::on_end(uint32_t now_ms) {
  if (state_ != State::receiving) return answer(CalStep::end, CalResult::locked, 0);
  const auto got = static_cast<uint8_t>(received_);
  const bool stale = elapsed(now_ms, last_activity_ms_, cfg_.frame_timeout_ms);
  const bool complete = received_ == kCalibrationBytes;
  const CalibrationBytes block = block_;
  const uint32_t want_crc = block_crc_;
  drop_block();  // whatever happens next, the block is used up and the service relocks
  if (stale) return answer(CalStep::end, CalResult::stale, got);
  if (!complete) return answer(CalStep::end, CalResult::incomplete, got);
  if (crc32(block.data(), block.size()) != want_crc) {
    return answer(CalStep::end, CalResult::crc_mismatch, 0);
  }
  Calibration c;
  if (!deserialize(block, c)) return answer(CalStep::end, CalResult::bad_format, block[0]);
  const int bad = first_out_of_range(c);
  if (bad >= 0) return answer(CalStep::end, CalResult::out_of_range, static_cast<uint8_t>(bad));
  if (apply_ != nullptr && !apply_(apply_context_, c)) {
    return answer(CalStep::end, CalResult::not_applied, 0, active_crc_);
  }
  active_ = c;
  active_crc_ = want_crc;
  ++applied_;
  CalTransferOutcome o = answer(CalStep::end, CalResult::accepted, 0, active_crc_);
  o.applied = true;
  return o;
}

bool CalibrationTransfer::tick(uint32_t now_ms, Mode mode, hal::CanFrame& reply) {
  if (state_ == State::receiving &&
      (mode != Mode::safe || elapsed(now_ms, last_activity_ms_, cfg_.frame_timeout_ms))) {
    const auto got = static_cast<uint8_t>(received_);
    drop_block();
    reply = answer(CalStep::timeout, CalResult::stale, got).reply;
    return true;
  }
  if (state_ != State::idle &&
      (mode != Mode::safe || elapsed(now_ms, last_activity_ms_, cfg_.unlock_timeout_ms))) {
    state_ = State::idle;
  }
  return false;
}

hal::CanFrame encode_cal_seed_request() {
  hal::CanFrame f = control_frame(kCalSeedRequestId, kDlc[0]);
  seal(f);
  return f;
}

hal::CanFrame encode_cal_key(uint32_t key) {
  hal::CanFrame f = control_frame(kCalKeyId, kDlc[1]);
  put_bits(f, 0, 32, key);
  seal(f);
  return f;
}

hal::CanFrame encode_cal_start(uint16_t length, uint32_t block_crc) {
  hal::CanFrame f = control_frame(kCalStartId, kDlc[2]);
  put_bits(f, 0, 16, length);
  put_bits(f, 16, 32, block_crc);
  seal(f);
  return f;
}

hal::CanFrame encode_cal_data(uint8_t seq, const uint8_t* bytes, unsigned n) {
  hal::CanFrame f = control_frame(kCalDataId, kDlc[3]);
  f.data[0] = seq;
  for (unsigned i = 0; i < n && i < kCalDataBytesPerFrame; ++i)
    f.data[1 + i] = bytes[i];
  return f;
}

hal::CanFrame encode_cal_end() {
  hal::CanFrame f = control_frame(kCalEndId, kDlc[4]);
  seal(f);
  return f;
}

bool decode_cal_reply(const hal::CanFrame& f, CalReply& out) {
  if (f.id != kCalReplyId || f.extended || f.len != 7) return false;
  out.step = static_cast<CalStep>(get_bits(f, 0, 4));
  out.result = static_cast<CalResult>(get_bits(f, 4, 4));
  out.detail = static_cast<uint8_t>(get_bits(f, 8, 8));
  out.value = static_cast<uint32_t>(get_bits(f, 16, 32));
  out.seq = static_cast<uint8_t>(get_bits(f, 48, 8));
  return true;
}

}  // namespace hrg::fw::can
