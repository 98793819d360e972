// SPDX-License-Identifier: MIT
#include "can/calibration_sender.hpp"

namespace hrg::can {

namespace {

using fw::can::CalReply;
using fw::can::CalResult;
using fw::can::CalStep;

// Sends a control frame and reads its reply; true when it was accepted.
bool exchange(CalBusIo& io, const hal::CanFrame& f, CalStep step, CalWriteResult& out) {
  io.send(f);
  out.answered = io.wait_reply(out.reply, kCalReplyTimeoutMs);
  return out.answered && out.reply.step == step && out.reply.result == CalResult::accepted;
}

// The DATA frames; false (with the refusal in `out`) when one was answered.
bool send_block(CalBusIo& io, const fw::CalibrationBytes& block, const CalWriteFaults& faults,
                CalWriteResult& out) {
  const unsigned n = fw::can::kCalDataBytesPerFrame;
  const auto frames = static_cast<int>((block.size() + n - 1) / n);
  for (int seq = 0; seq < frames; ++seq) {
    if (faults.stop_after_data >= 0 && seq >= faults.stop_after_data) break;
    if (seq == faults.skip_data_seq) continue;
    const std::size_t at = static_cast<std::size_t>(seq) * n;
    const auto len = static_cast<unsigned>(block.size() - at < n ? block.size() - at : n);
    io.send(fw::can::encode_cal_data(static_cast<uint8_t>(seq), block.data() + at, len));
  }
  // Accepted DATA frames are not answered: anything here is a refusal.
  CalReply r;
  if (io.wait_reply(r, 0)) {
    out.answered = true;
    out.reply = r;
    return false;
  }
  return true;
}

}  // namespace

CalWriteResult write_calibration(CalBusIo& io, const fw::Calibration& cal,
                                 const fw::can::CalSecret& secret, const CalWriteFaults& faults) {
  CalWriteResult out;
  if (!exchange(io, fw::can::encode_cal_seed_request(), CalStep::seed, out)) return out;
  uint32_t key = fw::can::calibration_key(out.reply.value, secret);
  if (faults.wrong_key) key ^= 1u;
  if (!exchange(io, fw::can::encode_cal_key(key), CalStep::key, out)) return out;
  const fw::CalibrationBytes block = fw::serialize(cal);
  uint32_t crc = fw::crc32(block.data(), block.size());
  if (faults.wrong_block_crc) crc ^= 0x80000000u;
  if (!exchange(io, fw::can::encode_cal_start(static_cast<uint16_t>(block.size()), crc),
                CalStep::start, out)) {
    return out;
  }
  if (!send_block(io, block, faults, out)) return out;
  if (faults.pause_before_end_ms > 0) io.pause(faults.pause_before_end_ms);
  io.send(fw::can::encode_cal_end());
  // A block that went stale meanwhile was answered on its own (step timeout)
  // before END's reply: that refusal is the one that tells.
  CalReply r;
  while (io.wait_reply(r, kCalReplyTimeoutMs)) {
    out.answered = true;
    out.reply = r;
    if (r.step == CalStep::end || r.result != CalResult::accepted) break;
  }
  return out;
}

bool parse_secret(std::string_view hex, fw::can::CalSecret& out) {
  if (hex.size() != 2 * out.size()) return false;
  auto nibble = [](char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < out.size(); ++i) {
    const int hi = nibble(hex[2 * i]);
    const int lo = nibble(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) return false;
    out[i] = static_cast<uint8_t>((hi << 4) | lo);
  }
  return true;
}

}  // namespace hrg::can
