// SPDX-License-Identifier: MIT
#pragma once

#include <span>

namespace hrg::cli {

// `hrg sim [--scenario FILE] [--duration S] [--out DIR] [--can-log FILE]`.
int sim_main(std::span<char* const> args);

}  // namespace hrg::cli
