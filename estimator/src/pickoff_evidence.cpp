// SPDX-License-Identifier: MIT
#include "estimator/pickoff_evidence.hpp"

#include <cmath>

namespace hrg::est {

double evidence_weighted(double x, double sigma, double k) {
  if (x == 0.0) return 0.0;
  const double share = 1.0 - k * sigma * sigma / (x * x);
  if (std::isnan(share)) return share;
  return share > 0.0 ? x * share : 0.0;
}

PickoffMapEstimate whole_estimate(const PickoffMap& in_force, const PickoffSelfCalResult& r) {
  PickoffMapEstimate e;
  e.value.gain = (1.0 + in_force.gain) * (1.0 + r.gain) - 1.0;
  e.value.misalignment_rad = in_force.misalignment_rad + r.misalignment_rad;
  e.value.phase_rad = in_force.phase_rad + r.phase_rad;
  e.sigma.gain = (1.0 + in_force.gain) * r.gain_sigma;
  e.sigma.misalignment_rad = r.misalignment_sigma_rad;
  e.sigma.phase_rad = r.phase_sigma_rad;
  return e;
}

PickoffMap evidence_weighted_map(const PickoffMap& in_force, const PickoffSelfCalResult& r) {
  const PickoffMapEstimate e = whole_estimate(in_force, r);
  return {evidence_weighted(e.value.gain, e.sigma.gain),
          evidence_weighted(e.value.misalignment_rad, e.sigma.misalignment_rad),
          evidence_weighted(e.value.phase_rad, e.sigma.phase_rad)};
}

PickoffSelfCalResult step_between(const PickoffMap& from, const PickoffMap& to,
                                  const PickoffSelfCalResult& r) {
  PickoffSelfCalResult s = r;
  s.gain = (1.0 + to.gain) / (1.0 + from.gain) - 1.0;
  s.misalignment_rad = to.misalignment_rad - from.misalignment_rad;
  s.phase_rad = to.phase_rad - from.phase_rad;
  // The step's own level pattern, as the fit's columns read it.
  const double k = (1.0 + s.gain) * (1.0 + s.gain);
  const double rho = (k - 1.0) / (k + 1.0);
  const double bh = std::sin(2.0 * s.misalignment_rad) / (2.0 * std::sqrt(1.0 - rho * rho));
  s.level_8th_c = 0.5 * rho * rho - 2.0 * bh * bh;
  s.level_8th_s = -2.0 * rho * bh;
  return s;
}

}  // namespace hrg::est
