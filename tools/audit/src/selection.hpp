// SPDX-License-Identifier: MIT
#pragma once

// Pieces of the audit that look at one fitted model: the switching-edge
// statistic of drive feedthrough, the effective sample count and the
// locations of what a model leaves in its residuals.

#include <string>
#include <vector>

#include "audit/audit.hpp"
#include "fit.hpp"

namespace hrg::audit::detail {

struct FeedStat {
  bool testable = false;
  double dchi2 = 0.0;  // against no feedthrough, chi^2 with 4 degrees of freedom under null
  double c_x = 0.0, c_y = 0.0;      // |c_k| (V/V)
  std::array<double, 4> c_re_im{};  // re/im c_x, re/im c_y (V/V)
  double sigma = 0.0;               // of the larger |c_k|
  double threshold = 0.0;           // |c| at which the expected delta BIC is zero
  int edges = 0;
  int dropped = 0;  // switch-offs left out as control transients
};

// Jumps of the measured envelopes at the switching instants, against the
// free-decay model extrapolated to the edge, in the frame of the wave phase.
FeedStat feedthrough_stat(const Dataset& d, const Params& p, double ln_neff);

// Effective sample fraction from the lag-1 correlation of the block residuals.
double effective_fraction(const std::vector<double>& res, std::size_t n_free_res);

// The excitation segments' frequency against the free-decay model p: the
// weighted mean offset and its 1-sigma (rad/s), the mean pump_v^2 (V^2).
struct ForcedOffset {
  double mean_rad_s = 0.0;
  double sigma_rad_s = 0.0;
  double mean_v2 = 0.0;
};
ForcedOffset forced_offset(const Dataset& d, const Params& p);

// Where the model misfits, strongest first.
std::vector<Location> locate(const Dataset& d, const Params& p, const std::vector<double>& res,
                             bool use_forced, const FeedStat& ft);

}  // namespace hrg::audit::detail
