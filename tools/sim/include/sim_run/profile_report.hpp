// SPDX-License-Identifier: MIT
#pragma once

// `hrg sim --profile`: where the host time of a lockstep run goes, per
// firmware task (the executive's own timings) and per stage of the simulated
// target's read_block (SimTarget::set_profiling), so a speed regression shows
// which part grew.

#include <string>

#include "sim_run/run.hpp"

namespace hrg::sim_run {

std::string format_profile(const RunResult& r);

}  // namespace hrg::sim_run
