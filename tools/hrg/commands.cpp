// SPDX-License-Identifier: MIT
#include "hrg/command.hpp"

#include <array>

#include "audit/audit_command.hpp"
#include "hrg/sim_command.hpp"

namespace hrg::cli {

int scenario_check_main(std::span<char* const> args);  // scenario_check_command.cpp

namespace {
constexpr std::array<Command, 4> kCommands{{
    {"sim", "run the firmware against the simulated gyro (the main job)", &sim_main},
    {"audit", "locate sim/recording mismatches and name the left-out physics",
     &hrg::audit::audit_main},
    {"audit-bench", "confusion matrix of hrg audit on recordings with concealed effects",
     &hrg::audit::audit_bench_main},
    {"scenario-check", "validate simulator scenario files (TOML)", &scenario_check_main},
}};
}  // namespace

std::span<const Command> commands() { return kCommands; }

}  // namespace hrg::cli
