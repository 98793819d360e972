// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <vector>

#include "audit/audit.hpp"

namespace hrg::audit {

// Per-block series for the plots: measured and predicted wave variables of
// the free-decay blocks, before (baseline) and after (selected model).
struct PlotData {
  std::vector<double> t_s, theta_deg, a_meas, a_before, a_after, q_meas, q_before, q_after;
  std::vector<double> res_before, res_after;  // rms of the 4 residuals per block, noise units
  std::vector<int> segment;
};

// Writes DIR/audit_blocks.csv and runs tools/audit/scripts/plot_audit.py with
// /usr/bin/python3 to make DIR/residual_map.png and DIR/fit_before_after.png.
// Returns a one-line message (what was written, or why the PNGs are missing).
std::string write_plots(const PlotData& p, const AuditResult& r, const std::string& dir);

}  // namespace hrg::audit
