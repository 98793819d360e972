// SPDX-License-Identifier: MIT
#pragma once

#include "characterize/datasheet.hpp"
#include "characterize/procedures.hpp"

namespace hrg::characterize::proc {

void add_angle_dependent_bias(DataSheet& sheet, const DriftResult& d);
void add_limits(DataSheet& sheet, const LimitsResult& l);
void add_rundown(DataSheet& sheet, const RundownResult& r);

}  // namespace hrg::characterize::proc
