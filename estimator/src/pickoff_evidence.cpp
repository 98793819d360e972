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
  set_step_terms(s);
  return s;
}

}  // namespace hrg::est
