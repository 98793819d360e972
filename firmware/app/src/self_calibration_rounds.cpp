// SPDX-License-Identifier: MIT
#include "firmware/app/self_calibration_rounds.hpp"

#include <algorithm>
#include <cmath>

namespace hrg::fw::app {

namespace {

bool significant(const est::PickoffSelfCalResult& r, double n_sigma) {
  return std::fabs(r.gain) > n_sigma * r.gain_sigma ||
         std::fabs(r.misalignment_rad) > n_sigma * r.misalignment_sigma_rad ||
         std::fabs(r.phase_rad) > n_sigma * r.phase_sigma_rad;
}

// The estimate's information has grown by `factor` since `before` (every
// parameter's variance divided by it at least).
bool better_by(const est::PickoffSelfCalResult& r, const est::PickoffSelfCalResult& before,
               double factor) {
  const auto shrunk = [factor](double now, double then) {
    return now * now * factor <= then * then;
  };
  return shrunk(r.gain_sigma, before.gain_sigma) &&
         shrunk(r.misalignment_sigma_rad, before.misalignment_sigma_rad) &&
         shrunk(r.phase_sigma_rad, before.phase_sigma_rad);
}

// |x - from| in sigmas; 0 for no sigma (nothing held).
double sigmas_from(double x, double from, double sigma) {
  return sigma > 0.0 ? std::fabs(x - from) / sigma : 0.0;
}

}  // namespace

double withdrawal_decay_f_limit(int windows) {
  if (windows < 2) return kNotJudgedSigmas;
  return 1.0 + SelfCalibrationRounds::kWithdrawDecaySigmas *
                   std::sqrt(2.0 / static_cast<double>(windows - 1));
}

PerWindowSupport per_window_support(const est::PickoffSelfCalResult& r,
                                    const est::PickoffMap& in_force,
                                    const est::PickoffMap& before) {
  // The per-window fit's residual in place of the common-nu one.
  est::PickoffSelfCalResult pw = r;
  pw.gain = r.per_window_gain;
  pw.gain_sigma = r.per_window_gain_sigma;
  pw.misalignment_rad = r.per_window_misalignment_rad;
  pw.misalignment_sigma_rad = r.per_window_misalignment_sigma_rad;
  const est::PickoffMapEstimate e = est::whole_estimate(in_force, pw);
  PerWindowSupport s;
  if (in_force.gain != before.gain)
    s.gain_sigmas = sigmas_from(e.value.gain, before.gain, e.sigma.gain);
  if (in_force.misalignment_rad != before.misalignment_rad) {
    s.misalignment_sigmas =
        sigmas_from(e.value.misalignment_rad, before.misalignment_rad, e.sigma.misalignment_rad);
  }
  return s;
}

est::PickoffMap withdrawal_target(const PerWindowSupport& s, const est::PickoffMap& in_force,
                                  const est::PickoffMap& before) {
  est::PickoffMap target = in_force;
  if (s.gain_sigmas <= SelfCalibrationRounds::kSignificance) target.gain = before.gain;
  if (s.misalignment_sigmas <= SelfCalibrationRounds::kSignificance)
    target.misalignment_rad = before.misalignment_rad;
  return target;
}

SelfCalibrationDecision SelfCalibrationRounds::decide(const est::PickoffSelfCalResult& r,
                                                      const est::PickoffMap& in_force) const {
  if (status_.withdrawn || r.status != est::Status::ok) return {};
  if (status_.rounds > 0 && r.decay_f > withdrawal_decay_f_limit(r.windows)) {
    const PerWindowSupport s = per_window_support(r, in_force, status_.before);
    const est::PickoffMap target = withdrawal_target(s, in_force, status_.before);
    if (!(target == in_force)) {
      return {SelfCalibrationAction::withdraw, target, est::step_between(in_force, target, r),
              std::min(s.gain_sigmas, s.misalignment_sigmas)};
    }
  }
  return next_round(r, in_force);
}

SelfCalibrationDecision SelfCalibrationRounds::next_round(const est::PickoffSelfCalResult& r,
                                                          const est::PickoffMap& in_force) const {
  // Nothing while one decay rate does not hold across the windows: a damping
  // that changes between them reads as a level pattern.
  if (!r.decay_consistent || status_.rounds >= kMaxRounds) return {};
  // First an estimate that stands out of its noise; then the residual of
  // every window so far (re-referred through what is in force) whenever it
  // stands out, or the information behind it has doubled.
  const bool apply =
      significant(r, kSignificance) || (status_.rounds > 0 && better_by(r, status_.applied, 2.0));
  if (!apply) return {};
  // Each part of the whole estimate (what is in force composed with the
  // residual) weighted by its evidence: a part within its noise of zero
  // would only add its noise to the output, and a part an earlier round
  // applied is judged again with every window since.
  const est::PickoffMap target = est::evidence_weighted_map(in_force, r);
  if (target == in_force) return {};
  return {SelfCalibrationAction::apply, target, est::step_between(in_force, target, r), 0.0};
}

void SelfCalibrationRounds::done(const SelfCalibrationDecision& d,
                                 const est::PickoffSelfCalResult& r,
                                 const est::PickoffMap& in_force, double t_s) {
  if (d.action == SelfCalibrationAction::apply) {
    if (status_.rounds == 0) status_.before = in_force;
    ++status_.rounds;
    status_.applied = d.step;
    status_.applied_s = t_s;
  } else if (d.action == SelfCalibrationAction::withdraw) {
    status_.withdrawn = true;
    status_.withdrawn_s = t_s;
    status_.withdrawn_decay_f = r.decay_f;
    status_.withdrawn_decay_f_limit = withdrawal_decay_f_limit(r.windows);
    status_.withdrawn_support_sigmas = d.support_sigmas;
  }
}

est::PickoffMap SelfCalibrationRounds::map_to_keep(const est::PickoffSelfCalResult& r,
                                                   const est::PickoffMap& in_force) const {
  if (status_.withdrawn || r.status != est::Status::ok || !r.decay_consistent) return in_force;
  if (status_.rounds == 0 && !significant(r, kSignificance)) return in_force;
  return est::evidence_weighted_map(in_force, r);
}

}  // namespace hrg::fw::app
