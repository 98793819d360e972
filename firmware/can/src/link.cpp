// SPDX-License-Identifier: MIT
#include "firmware/can/link.hpp"

namespace hrg::fw::can {

namespace {
constexpr int kMaxFramesPerPoll = 16;  // bounds the time spent per base frame
}

CanLink::CanLink(hal::CanBus& bus, uint32_t restart_after_frames,
                 const CalTransferConfig& calibration)
    : bus_(bus),
      restart_after_frames_(restart_after_frames),
      calibration_(calibration, kIdentityCalibration) {}

hal::Status CanLink::init() {
  const hal::CanFilter ours[] = {{kCommandIdFirst, 0x7F0}, {kCalSeedRequestId, 0x7F8}};
  return bus_.set_filters(ours);
}

bool CanLink::poll(const ControllerView& state, Command& out, uint32_t now_ms, uint32_t entropy) {
  for (int i = 0; i < kMaxFramesPerPoll; ++i) {
    hal::CanFrame f;
    if (bus_.receive(f) != hal::Status::ok) return false;
    if (!f.extended && CalibrationTransfer::is_calibration_id(f.id)) {
      const CalTransferOutcome c = calibration_.process(f, state.mode, now_ms, entropy);
      if (c.reply_ready) send({&c.reply, 1});
      continue;
    }
    const CommandOutcome o = validator_.process(f, state);
    if (!o.for_us) continue;
    send({&o.reply, 1});
    if (o.result != CommandResult::accepted) {
      ++stats_.commands_refused;
      continue;
    }
    ++stats_.commands_accepted;
    out = o.command;
    return true;
  }
  return false;
}

void CanLink::tick_calibration(uint32_t now_ms, Mode mode) {
  hal::CanFrame reply;
  if (calibration_.tick(now_ms, mode, reply)) send({&reply, 1});
}

void CanLink::send(std::span<const hal::CanFrame> frames) {
  for (const auto& f : frames) {
    if (bus_.send(f) != hal::Status::ok) ++stats_.tx_refused;
  }
}

void CanLink::service() {
  if (bus_.state() != hal::CanState::bus_off) {
    off_frames_ = 0;
    return;
  }
  if (++off_frames_ < restart_after_frames_) return;
  off_frames_ = 0;
  ++stats_.restarts;
  bus_.restart();
}

}  // namespace hrg::fw::can
