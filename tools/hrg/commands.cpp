// SPDX-License-Identifier: MIT
#include "hrg/command.hpp"

#include <array>

namespace hrg::cli {

namespace {
constexpr std::array<Command, 0> kCommands{};
}  // namespace

std::span<const Command> commands() { return kCommands; }

}  // namespace hrg::cli
