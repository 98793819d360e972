// SPDX-License-Identifier: MIT
#include "hrg/command.hpp"

#include <array>

#include "audit/audit_command.hpp"
#include "can/calibration_sender.hpp"
#include "can/can_decode.hpp"
#include "hrg/sim_command.hpp"

namespace hrg::cli {

int scenario_check_main(std::span<char* const> args);     // scenario_check_command.cpp
int characterize_main(std::span<char* const> args);       // characterize_command.cpp
int calibration_check_main(std::span<char* const> args);  // calibration_check_command.cpp
int study_main(std::span<char* const> args);              // study_command.cpp

namespace {
constexpr std::array<Command, 9> kCommands{{
    {"sim", "run the firmware against the simulated gyro (the main job)", &sim_main},
    {"audit", "locate sim/recording mismatches and name the left-out physics",
     &hrg::audit::audit_main},
    {"characterize", "IEEE 1431 / 952 test procedures on the simulated gyro: the data sheet",
     &characterize_main},
    {"study", "tolerance: the firmware over a grid of resonators against the Cramer-Rao bound",
     &study_main},
    {"audit-bench", "confusion matrix of hrg audit on recordings with concealed effects",
     &hrg::audit::audit_bench_main},
    {"can-decode", "turn a candump log of the CAN telemetry into an hrg-recording v1",
     &hrg::can::can_decode_main},
    {"can-calibrate", "write a calibration file into a gyro over CAN (guarded write)",
     &hrg::can::can_calibrate_main},
    {"scenario-check", "validate simulator scenario files (TOML)", &scenario_check_main},
    {"calibration-check", "validate a calibration file (TOML); write it as a C++ constant",
     &calibration_check_main},
}};
}  // namespace

std::span<const Command> commands() { return kCommands; }

}  // namespace hrg::cli
