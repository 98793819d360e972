// SPDX-License-Identifier: MIT
// SelfCalibrationRounds: the online pickoff self-calibration applies a round
// on a solve whose decay test passed, withdraws its rounds when that test
// later refutes one decay rate and its per-window fit does not hold them,
// and keeps for the next power-up the map before them.
#include "firmware/app/self_calibration_rounds.hpp"

#include <cmath>

#include "support/cpputest.hpp"

using hrg::est::PickoffMap;
using hrg::est::PickoffSelfCalResult;
using hrg::fw::app::per_window_support;
using hrg::fw::app::SelfCalibrationAction;
using hrg::fw::app::SelfCalibrationDecision;
using hrg::fw::app::SelfCalibrationRounds;
using hrg::fw::app::withdrawal_decay_f_limit;

namespace {

constexpr double kDegRad = 3.14159265358979323846 / 180.0;

// A solve of `windows` windows with residual gain g +- sg, the decay test's
// F, and the per-window fit's gain; misalignment and phase 0 within the
// noise of the thermal damping row (tools/gregory, variants, seed 3).
PickoffSelfCalResult solve(int windows, double g, double sg, double decay_f, double pw_g,
                           double pw_sg) {
  PickoffSelfCalResult r;
  r.status = hrg::est::Status::ok;
  r.windows = windows;
  r.samples = 1000 * windows;
  r.gain = g;
  r.gain_sigma = sg;
  r.misalignment_sigma_rad = 7e-4 * kDegRad;
  r.phase_sigma_rad = 1.4e-3 * kDegRad;
  r.decay_f = decay_f;
  r.decay_f_limit = 1.0 + hrg::est::kSelfCalDecaySigmas * std::sqrt(2.0 / (windows - 1));
  r.decay_consistent = r.decay_f <= r.decay_f_limit;
  r.per_window_gain = pw_g;
  r.per_window_gain_sigma = pw_sg;
  r.per_window_misalignment_sigma_rad = 6e-3 * kDegRad;
  return r;
}

// Carries out `d` as the firmware does: the map in force becomes its target.
PickoffMap carry_out(SelfCalibrationRounds& rounds, const SelfCalibrationDecision& d,
                     const PickoffSelfCalResult& r, const PickoffMap& in_force, double t_s) {
  if (d.action == SelfCalibrationAction::none) return in_force;
  rounds.done(d, r, in_force, t_s);
  return d.target;
}

// The round the thermal damping row applied at 167.5 s: -1.39e-4 +- 2.77e-5
// (5.02 sigma) with the decay test passing on 40 windows.
PickoffMap first_round(SelfCalibrationRounds& rounds, const PickoffMap& before) {
  const PickoffSelfCalResult r = solve(40, -1.39e-4, 2.77e-5, 1.5, 0.0, 2.8e-4);
  const SelfCalibrationDecision d = rounds.decide(r, before);
  CHECK(d.action == SelfCalibrationAction::apply);
  return carry_out(rounds, d, r, before, 167.5);
}

}  // namespace

TEST_GROUP(SelfCalibrationRounds){};

TEST(SelfCalibrationRounds, ARoundItsDecayTestLaterRefutesIsWithdrawnAndTheMapBeforeItKept) {
  // GIVEN a round applied on windows whose decay test passed
  SelfCalibrationRounds rounds;
  const PickoffMap identity{};
  const PickoffMap in_force = first_round(rounds, identity);
  // evidence-weighted: x (1 - sigma^2 / x^2)
  DOUBLES_EQUAL(-1.39e-4 * (1.0 - 2.77e-5 * 2.77e-5 / (1.39e-4 * 1.39e-4)), in_force.gain, 1e-12);
  CHECK_EQUAL(1u, rounds.status().rounds);
  // WHEN the windows since refute one decay rate (the row at its end: F 12.8
  // on 57 windows, limit 2.51) and the per-window fit reads the residual
  // +1.95e-4 +- 2.8e-4: the whole gain 6.1e-5, 0.22 of its sigma from 0
  const PickoffSelfCalResult late = solve(57, 9.2e-5, 1.1e-5, 12.77, 1.95e-4, 2.8e-4);
  const SelfCalibrationDecision d = rounds.decide(late, in_force);
  // THEN the rounds are withdrawn: back to the map before them, the model's
  // windows re-referred by the step back
  CHECK(d.action == SelfCalibrationAction::withdraw);
  CHECK(d.target == identity);
  DOUBLES_EQUAL(1.0 / (1.0 + in_force.gain) - 1.0, d.step.gain, 1e-15);
  DOUBLES_EQUAL((-1.3354e-4 + 1.95e-4) / 2.8e-4, d.support_sigmas, 1e-3);
  const PickoffMap after = carry_out(rounds, d, late, in_force, 191.6);
  CHECK_TRUE(rounds.status().withdrawn);
  DOUBLES_EQUAL(191.6, rounds.status().withdrawn_s, 0.0);
  DOUBLES_EQUAL(12.77, rounds.status().withdrawn_decay_f, 0.0);
  DOUBLES_EQUAL(1.0 + 8.0 * std::sqrt(2.0 / 56.0), rounds.status().withdrawn_decay_f_limit, 1e-12);
  // AND the map kept for the next power-up is the one before the rounds,
  // even where a later solve would pass and stand out: nothing more applied
  CHECK(rounds.map_to_keep(late, after) == identity);
  const PickoffSelfCalResult clean = solve(70, -2e-4, 2e-5, 1.2, 0.0, 2.8e-4);
  CHECK(rounds.decide(clean, after).action == SelfCalibrationAction::none);
  CHECK(rounds.map_to_keep(clean, after) == identity);
}

TEST(SelfCalibrationRounds, ADecayTestRefusalWithinItsFalseAlarmRateWithdrawsNothing) {
  // GIVEN the same round
  SelfCalibrationRounds rounds;
  const PickoffMap in_force = first_round(rounds, {});
  // WHEN the decay test refuses above its pass limit (1.91 on 40 windows)
  // but below the withdrawal's (2.81), the per-window fit holding nothing
  const PickoffSelfCalResult r = solve(40, 1e-5, 2.7e-5, 2.5, 1.39e-4, 2.8e-4);
  CHECK_FALSE(r.decay_consistent);
  // THEN the round stays (and no round is applied on the refused windows)
  CHECK(rounds.decide(r, in_force).action == SelfCalibrationAction::none);
  CHECK_FALSE(rounds.status().withdrawn);
  // AND just above the withdrawal's limit it goes
  const PickoffSelfCalResult refuted = solve(40, 1e-5, 2.7e-5, 2.82, 1.39e-4, 2.8e-4);
  CHECK(rounds.decide(refuted, in_force).action == SelfCalibrationAction::withdraw);
}

TEST(SelfCalibrationRounds, ARealPickoffTheDecayTestRefusesStaysInForce) {
  // GIVEN a 1 % gain applied (1000 sigma)
  SelfCalibrationRounds rounds;
  const PickoffSelfCalResult r0 = solve(30, 0.01, 1e-5, 1.2, 0.0, 5e-5);
  const PickoffMap in_force = carry_out(rounds, rounds.decide(r0, {}), r0, {}, 120.0);
  DOUBLES_EQUAL(0.01, in_force.gain, 1e-8);
  // WHEN one decay rate fails far beyond the withdrawal's limit (F 4.6 on
  // 100 windows, limit 2.14) while the per-window fit still holds the gain
  // (residual 2e-6 +- 5e-6: the whole 0.010002, 2000 sigma from 0)
  const PickoffSelfCalResult r = solve(100, 3e-6, 2e-6, 4.6, 2e-6, 5e-6);
  CHECK(per_window_support(r, in_force, {}).gain_sigmas > 1000.0);
  // THEN the correction stays in force, and the board keeps it
  CHECK(rounds.decide(r, in_force).action == SelfCalibrationAction::none);
  CHECK_FALSE(rounds.status().withdrawn);
  CHECK(rounds.map_to_keep(r, in_force) == in_force);
}

TEST(SelfCalibrationRounds, AWithdrawalGoesBackToTheFilesMapNotTheIdentity) {
  // GIVEN a file's map in force, then a round on top of it
  SelfCalibrationRounds rounds;
  const PickoffMap file{0.005, 0.2 * kDegRad, 0.1 * kDegRad};
  const PickoffMap in_force = first_round(rounds, file);
  CHECK(in_force.gain != file.gain);
  CHECK(rounds.status().before == file);
  // WHEN refuted, THEN the gain and misalignment are the file's again (the
  // phase, which the decay test does not judge, as the round weighed it:
  // 0.1 deg x (1 - (1.4e-3 / 0.1)^2)), and that is what is kept
  const PickoffSelfCalResult late = solve(57, 9.2e-5, 1.1e-5, 12.77, 1.95e-4, 2.8e-4);
  const SelfCalibrationDecision d = rounds.decide(late, in_force);
  CHECK(d.action == SelfCalibrationAction::withdraw);
  DOUBLES_EQUAL(file.gain, d.target.gain, 0.0);
  DOUBLES_EQUAL(file.misalignment_rad, d.target.misalignment_rad, 0.0);
  DOUBLES_EQUAL(in_force.phase_rad, d.target.phase_rad, 0.0);
  const PickoffMap after = carry_out(rounds, d, late, in_force, 191.6);
  CHECK(rounds.map_to_keep(late, after) == after);
}

TEST(SelfCalibrationRounds, APhaseRoundIsNotJudgedByTheDecayTest) {
  // GIVEN a round that changed only the phase (the quadrature row: no decay
  // rate in it), gain and misalignment within their noise
  SelfCalibrationRounds rounds;
  PickoffSelfCalResult r0 = solve(30, 1e-6, 1e-5, 1.2, 0.0, 5e-5);
  r0.phase_rad = 1.0 * kDegRad;
  const PickoffMap in_force = carry_out(rounds, rounds.decide(r0, {}), r0, {}, 120.0);
  DOUBLES_EQUAL(0.0, in_force.gain, 0.0);
  CHECK(in_force.phase_rad > 0.99 * kDegRad);
  // WHEN one decay rate fails far beyond the withdrawal's limit
  const PickoffSelfCalResult r = solve(100, 1e-6, 1e-5, 6.0, 0.0, 5e-5);
  // THEN the phase stays
  CHECK(rounds.decide(r, in_force).action == SelfCalibrationAction::none);
}

TEST(SelfCalibrationRounds, TheWithdrawalsLimitIsTwiceThePassLimitsSigmas) {
  // F's standard deviation under one decay rate is sqrt(2 / (W - 1)).
  DOUBLES_EQUAL(1.0 + 8.0 * std::sqrt(0.2), withdrawal_decay_f_limit(11), 1e-12);
  DOUBLES_EQUAL(1.0 + 8.0 * std::sqrt(2.0 / 56.0), withdrawal_decay_f_limit(57), 1e-12);
  CHECK(withdrawal_decay_f_limit(1) > 1e100);  // one window: no test
}

TEST(SelfCalibrationRounds, OnlyThePartsThePerWindowFitDoesNotHoldAreWithdrawn) {
  // GIVEN a round that put in force a 0.5 deg misalignment (1000 sigma), a
  // 1 deg phase and a gain of 1.39e-4 (5.02 sigma)
  SelfCalibrationRounds rounds;
  PickoffSelfCalResult r0 = solve(40, -1.39e-4, 2.77e-5, 1.5, 0.0, 2.8e-4);
  r0.misalignment_rad = 0.5 * kDegRad;
  r0.phase_rad = 1.0 * kDegRad;
  const PickoffMap in_force = carry_out(rounds, rounds.decide(r0, {}), r0, {}, 120.0);
  CHECK(in_force.gain != 0.0);
  // WHEN one decay rate is refuted and the per-window fit holds the
  // misalignment (residual 1e-4 deg +- 6e-3 deg) but not the gain
  const PickoffSelfCalResult r = solve(57, 9.2e-5, 1.1e-5, 12.77, 1.95e-4, 2.8e-4);
  const SelfCalibrationDecision d = rounds.decide(r, in_force);
  // THEN the gain goes back, the misalignment and the phase stay
  CHECK(d.action == SelfCalibrationAction::withdraw);
  DOUBLES_EQUAL(0.0, d.target.gain, 0.0);
  DOUBLES_EQUAL(in_force.misalignment_rad, d.target.misalignment_rad, 0.0);
  DOUBLES_EQUAL(in_force.phase_rad, d.target.phase_rad, 0.0);
  const PickoffMap after = carry_out(rounds, d, r, in_force, 191.6);
  CHECK(rounds.map_to_keep(r, after) == after);
}
