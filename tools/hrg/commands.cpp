// SPDX-License-Identifier: MIT
#include "hrg/command.hpp"

#include <array>

#include "audit/audit_command.hpp"

namespace hrg::cli {

namespace {
constexpr std::array<Command, 1> kCommands{{
    {"audit", "locate sim/recording mismatches and name the left-out physics",
     &hrg::audit::audit_main},
}};
}  // namespace

std::span<const Command> commands() { return kCommands; }

}  // namespace hrg::cli
