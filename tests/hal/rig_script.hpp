// SPDX-License-Identifier: MIT
#pragma once

#include <vector>

#include "firmware/can/command.hpp"

namespace hrg::rig {

// One scripted command of the VM test and the reply result it must get.
struct Step {
  const char* name;
  hal::CanFrame frame;
  fw::can::CommandResult expect;
};

// The command sequence tools/vm/guest-test.sh sends with cansend, in order.
const std::vector<Step>& script();

// Checks a candump -L capture of a scripted rig run; prints figures; 0 = pass.
int check_log(const char* path);
// Checks a candump -L capture of hrg-board (the firmware on this target): all
// telemetry present (at most 1 % lost), a status request and a window
// schedule accepted by the firmware's command task.
int check_firmware_log(const char* path);
// Writes a deterministic telemetry log with CandumpLogWriter (for canplayer).
int write_replay_log(const char* path);
// Checks that a capture of the replay holds exactly the frames of write_replay_log.
int check_replay(const char* path);

}  // namespace hrg::rig
