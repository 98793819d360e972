// SPDX-License-Identifier: MIT
#pragma once

#include <span>
#include <string_view>

namespace hrg::cli {

// One subcommand of `hrg`. `run` gets the arguments after the subcommand name
// and returns the process exit code.
struct Command {
  std::string_view name;
  std::string_view summary;
  int (*run)(std::span<char* const> args);
};

// The table of subcommands, in the order `hrg --help` lists them.
std::span<const Command> commands();

}  // namespace hrg::cli
