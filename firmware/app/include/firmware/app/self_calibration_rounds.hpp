// SPDX-License-Identifier: MIT
#pragma once

// When the online pickoff self-calibration puts a round in force, when it
// takes its rounds back, and which map a board keeps for the next power-up.
// Pure decisions on the estimator's solves (est::PickoffSelfCalResult), so a
// test can script them; Firmware::self_calibrate carries them out.
//
// A round is solved with one decay rate across the windows; the per-window
// decay test (decay_f) passing is what lets the firmware read the level
// patterns as a gain or a misalignment. A damping that changes between the
// windows (temperature, amplitude) and correlates with their pattern angles
// reads as a level pattern too, and the test may pass on the windows of the
// round and refuse them later. Refuted then means both:
// - the decay test refuses at kWithdrawDecaySigmas (twice the sigmas it
//   passes up to): its F under one decay rate is chi^2(W - 1) / (W - 1), and
//   its false alarm per solve is 1.6e-6 at W = 11 and below 1e-8 from W = 44
//   on (1.9e-3 and 5e-4 at the pass limit, which a run's ~50-300 solves
//   would cross by noise alone); F moves only with the windows folded since
//   the round (re-referring the windows through a round leaves it as it is),
//   so this is evidence from after the round;
// - the decay test's own fit (a decay rate per window, which a damping
//   changing between windows cannot bias into the level patterns) does not
//   hold a gain or misalignment the rounds changed out of its noise
//   (kSignificance from the map before the rounds). A pickoff a round
//   corrected is still there in that fit, and stays: one decay rate can fail
//   on a real pickoff too (tools/gregory, pickoff combination, 1800 s,
//   seed 1: F 3.14 against the withdrawal's 2.09, the gain and the
//   misalignment held at 2490 and 2990 sigmas).
// Each such part then goes back to the map before the rounds (all of them
// where the rounds were the refuted model's alone); the phase, from the
// quadrature row, has no decay rate in it and stays. Once, for the rest of
// the run: nothing more is applied after a withdrawal (no toggling).
//
// Freestanding, no heap.

#include <cstdint>

#include "estimator/pickoff_evidence.hpp"

namespace hrg::fw::app {

// What the online pickoff self-calibration has put in force.
struct SelfCalibrationStatus {
  uint32_t rounds = 0;  // estimates applied (each restarts the model)
  // The last step applied (est::step_between: what it changed in the map,
  // with the sigmas of the solve it was weighed on).
  est::PickoffSelfCalResult applied{};
  double applied_s = 0.0;  // when
  // The map in force before the first round (the file's or the identity):
  // what a withdrawal goes back to, part by part.
  est::PickoffMap before{};
  // The rounds were withdrawn (their model refuted, above), when, and the
  // evidence: the decay test's F against the withdrawal's limit, and how
  // many of its sigmas the per-window fit holds the parts the rounds
  // changed from `before` (the smaller of gain and misalignment).
  bool withdrawn = false;
  double withdrawn_s = 0.0;
  double withdrawn_decay_f = 0.0;
  double withdrawn_decay_f_limit = 0.0;
  double withdrawn_support_sigmas = 0.0;
};

enum class SelfCalibrationAction : uint8_t {
  none,      // nothing to change
  apply,     // put a round in force
  withdraw,  // take back what the rounds changed that their refuted model alone held
};

struct SelfCalibrationDecision {
  SelfCalibrationAction action = SelfCalibrationAction::none;
  est::PickoffMap target{};          // the map to put in force
  est::PickoffSelfCalResult step{};  // from the map in force to it (refer_to_applied)
  double support_sigmas = 0.0;       // withdraw: the per-window fit's support
};

// The decay test's limit for a withdrawal with `windows` windows (F's
// standard deviation under one decay rate is sqrt(2 / (W - 1))).
double withdrawal_decay_f_limit(int windows);

// Where a figure judges nothing (a part the rounds did not change, a test
// on one window).
inline constexpr double kNotJudgedSigmas = 1e300;

// How many sigmas the decay test's own fit (a decay rate per window) holds
// each part of the whole estimate (in_force composed with its residual)
// away from `before`, for the gain and the misalignment in_force changed
// from `before`; 0 where that fit holds no pickoff map (sigma 0). The phase,
// from the quadrature row, is not what the decay test judges.
struct PerWindowSupport {
  double gain_sigmas = kNotJudgedSigmas;
  double misalignment_sigmas = kNotJudgedSigmas;
};
PerWindowSupport per_window_support(const est::PickoffSelfCalResult& r,
                                    const est::PickoffMap& in_force, const est::PickoffMap& before);
// The map a withdrawal puts in force: `in_force` with each part the
// per-window fit does not hold out of its noise (SelfCalibrationRounds::
// kSignificance) back to `before`'s.
est::PickoffMap withdrawal_target(const PerWindowSupport& s, const est::PickoffMap& in_force,
                                  const est::PickoffMap& before);

class SelfCalibrationRounds {
 public:
  // A round is applied when the solve is accepted (conditioning, one decay
  // rate across the windows) and the estimate stands out of its own noise by
  // this many sigma; later, when the residual over every window stands out
  // or its information has doubled since the last round; at most kMaxRounds
  // times. A round puts each part of the whole estimate in force weighted by
  // its evidence (est::evidence_weighted_map).
  static constexpr double kSignificance = 5.0;
  static constexpr uint32_t kMaxRounds = 4;
  static constexpr double kWithdrawDecaySigmas = 2.0 * est::kSelfCalDecaySigmas;

  // Once per fresh solve `r`, read through the map `in_force`.
  SelfCalibrationDecision decide(const est::PickoffSelfCalResult& r,
                                 const est::PickoffMap& in_force) const;
  // The firmware has put `d` (decided on `r` with `in_force`) in force at t_s.
  void done(const SelfCalibrationDecision& d, const est::PickoffSelfCalResult& r,
            const est::PickoffMap& in_force, double t_s);
  // The pickoff map a board keeps for the next power-up: what a round would
  // put in force now once a round has been applied or the estimate stands
  // out; else the map in force (also while the solve fails, the decay test
  // refuses its windows, or after a withdrawal: the map it left).
  est::PickoffMap map_to_keep(const est::PickoffSelfCalResult& r,
                              const est::PickoffMap& in_force) const;
  const SelfCalibrationStatus& status() const { return status_; }

 private:
  SelfCalibrationDecision next_round(const est::PickoffSelfCalResult& r,
                                     const est::PickoffMap& in_force) const;
  SelfCalibrationStatus status_{};
};

}  // namespace hrg::fw::app
