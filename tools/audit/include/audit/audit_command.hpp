// SPDX-License-Identifier: MIT
#pragma once

#include <span>

namespace hrg::audit {

// Entry points of the `hrg audit` and `hrg audit-bench` subcommands
// (arguments after the subcommand name; return the exit code).
int audit_main(std::span<char* const> args);
int audit_bench_main(std::span<char* const> args);

}  // namespace hrg::audit
