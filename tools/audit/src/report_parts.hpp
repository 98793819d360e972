// SPDX-License-Identifier: MIT
#pragma once

// Parts of the human report that read the fitted model: the impact of a
// finding in gyro units, the per-block series of the plots and the locations
// each candidate points at.

#include <string>

#include "audit/audit.hpp"
#include "audit/plots.hpp"
#include "model.hpp"

namespace hrg::audit::detail {

// Impact of effect `e` with catalogue value `v` in gyro units (deg, deg/h, mHz, Q).
std::string impact_text(const Dataset& d, const Params& p, Effect e, double v);

// Measured and predicted wave variables per free-decay block, before and after.
void fill_plot(const Dataset& d, const EvalOptions& eo, const Params& before, const Params& after,
               PlotData& plot);

// Appends, for each candidate with some evidence, where it sees the baseline's
// misfit and over which range of its quantity.
void add_candidate_locations(const Dataset& d, AuditResult& out);

}  // namespace hrg::audit::detail
