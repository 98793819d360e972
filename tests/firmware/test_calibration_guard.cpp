// SPDX-License-Identifier: MIT
// CalibrationGuard: a calibration put in force is judged by the first check
// window after the campaign, and withdrawn when that one disagrees.
#include "firmware/app/calibration_guard.hpp"

#include "support/cpputest.hpp"

using hrg::fw::EstimatorHealth;
using hrg::fw::app::CalibrationGuard;
using hrg::fw::app::CalibrationSource;
using hrg::fw::app::CalibrationVerdict;

namespace {

constexpr double kMinMisfit = 0.25;
constexpr double kMaxMisfit = 4.0;

EstimatorHealth checked(uint32_t windows, double misfit) {
  EstimatorHealth h;
  h.windows_checked = windows;
  h.window_misfit = misfit;
  return h;
}

}  // namespace

TEST_GROUP(CalibrationGuard){};

TEST(CalibrationGuard, TheIdentityIsNotJudged) {
  CalibrationGuard g(kMinMisfit, kMaxMisfit);
  g.applied(CalibrationSource::file, 0, true, 0.0, {}, false);
  CHECK(g.status().source == CalibrationSource::none);
  CHECK_FALSE(g.judge(checked(5, 100.0), true, 1.0));
  CHECK(g.status().verdict == CalibrationVerdict::none);
}

TEST(CalibrationGuard, CampaignWindowsAreNoVerdictTheFirstCheckAfterIs) {
  CalibrationGuard g(kMinMisfit, kMaxMisfit);
  g.applied(CalibrationSource::file, 7, false, 0.0, {}, false);
  // Windows checked during the campaign (an early model) and the one that
  // ends it prove nothing, whatever their misfit.
  CHECK_FALSE(g.judge(checked(3, 90.0), false, 50.0));
  CHECK_FALSE(g.judge(checked(4, 90.0), true, 100.0));
  CHECK(g.status().verdict == CalibrationVerdict::on_trial);
  // The first check window after the campaign: above the noise, no check
  // before it to compare with: withdrawn.
  CHECK_TRUE(g.judge(checked(5, 4.5), true, 120.0));
  CHECK(g.status().verdict == CalibrationVerdict::withdrawn);
  DOUBLES_EQUAL(4.5, g.status().misfit_after, 0.0);
  DOUBLES_EQUAL(120.0, g.status().judged_s, 0.0);
  CHECK_EQUAL(1u, g.status().withdrawals);
  // Judged once: nothing more to withdraw.
  CHECK_FALSE(g.judge(checked(6, 90.0), true, 140.0));
}

TEST(CalibrationGuard, ACheckWithinTheNoiseConfirms) {
  CalibrationGuard g(kMinMisfit, kMaxMisfit);
  g.applied(CalibrationSource::can, 7, false, 0.0, checked(2, 1.0), true);
  CHECK_FALSE(g.judge(checked(2, 1.0), true, 1.0));  // no new check yet
  CHECK_FALSE(g.judge(checked(3, 3.9), true, 2.0));
  CHECK(g.status().verdict == CalibrationVerdict::confirmed);
  CHECK(g.status().source == CalibrationSource::can);
}

TEST(CalibrationGuard, AWindowFarQuieterThanTheModelsResidualNeitherConfirmsNorWithdraws) {
  // A check misfit of 0.02 means the model's residual sigma is 50x what the
  // window shows: it absorbed structure as noise, so the window cannot tell
  // a right calibration from a wrong one. The calibration stays on trial;
  // the next window in the band judges it.
  CalibrationGuard g(kMinMisfit, kMaxMisfit);
  g.applied(CalibrationSource::file, 7, false, 0.0, checked(2, 1.0), true);
  CHECK_FALSE(g.judge(checked(3, 0.02), true, 2.0));
  CHECK(g.status().verdict == CalibrationVerdict::on_trial);
  DOUBLES_EQUAL(0.02, g.status().misfit_after, 0.0);
  CHECK_EQUAL(0u, g.status().withdrawals);
  // At the band's edge the window has its power back.
  CHECK_FALSE(g.judge(checked(4, kMinMisfit), true, 3.0));
  CHECK(g.status().verdict == CalibrationVerdict::confirmed);
  // The same quiet window after a misfit-30 check is no "better than
  // before" either: still on trial.
  CalibrationGuard online(kMinMisfit, kMaxMisfit);
  online.applied(CalibrationSource::online, 7, false, 200.0, checked(8, 30.0), true);
  CHECK_FALSE(online.judge(checked(9, 0.1), true, 220.0));
  CHECK(online.status().verdict == CalibrationVerdict::on_trial);
}

TEST(CalibrationGuard, AboveTheNoiseButBetterThanBeforeConfirms) {
  // Applied mid-run (online), after a check that already disagreed (misfit
  // 30): a check at 10 is not consistent with the noise but is better than
  // before: confirmed; at 31 it would have been withdrawn.
  CalibrationGuard g(kMinMisfit, kMaxMisfit);
  g.applied(CalibrationSource::online, 7, false, 200.0, checked(8, 30.0), true);
  DOUBLES_EQUAL(30.0, g.status().misfit_before, 0.0);
  CHECK_FALSE(g.judge(checked(9, 10.0), true, 220.0));
  CHECK(g.status().verdict == CalibrationVerdict::confirmed);
  CalibrationGuard worse(kMinMisfit, kMaxMisfit);
  worse.applied(CalibrationSource::online, 7, false, 200.0, checked(8, 30.0), true);
  CHECK_TRUE(worse.judge(checked(9, 31.0), true, 220.0));
}

// A calibration with a feedthrough part acts only while the pump runs,
// where no free-decay window looks: the switch-off step check judges it too.
TEST(CalibrationGuard, AFeedthroughCalibrationIsConfirmedOnlyOnceTheSwitchOffsShowNoStep) {
  using hrg::fw::PumpEdgeVerdict;
  CalibrationGuard g(kMinMisfit, kMaxMisfit);
  g.applied(CalibrationSource::file, 7, false, true, 0.0, {}, false);
  CHECK_TRUE(g.status().feedthrough);
  // The check window after the campaign agrees, the edges are not decided yet.
  CHECK_FALSE(g.judge(checked(4, 90.0), true, 100.0, PumpEdgeVerdict::unknown));
  CHECK_FALSE(g.judge(checked(5, 1.0), true, 120.0, PumpEdgeVerdict::unknown));
  CHECK(g.status().verdict == CalibrationVerdict::on_trial);
  CHECK_TRUE(g.status().window_agreed);
  // Then the edges are consistent: confirmed.
  CHECK_FALSE(g.judge(checked(5, 1.0), true, 121.0, PumpEdgeVerdict::consistent));
  CHECK(g.status().verdict == CalibrationVerdict::confirmed);
  // A step later still withdraws it.
  CHECK_TRUE(g.judge(checked(5, 1.0), true, 300.0, PumpEdgeVerdict::step));
  CHECK(g.status().verdict == CalibrationVerdict::withdrawn);
  CHECK(g.status().edge == PumpEdgeVerdict::step);
  DOUBLES_EQUAL(300.0, g.status().judged_s, 0.0);
  CHECK_EQUAL(1u, g.status().withdrawals);
}

TEST(CalibrationGuard, AStepWithdrawsAFeedthroughCalibrationAtOnceButNotAPickoffOne) {
  using hrg::fw::PumpEdgeVerdict;
  // GIVEN a feedthrough calibration, the campaign still running
  CalibrationGuard ft(kMinMisfit, kMaxMisfit);
  ft.applied(CalibrationSource::file, 7, false, true, 0.0, {}, false);
  // THEN a step at the first switch-off withdraws it (no model needed)
  CHECK_TRUE(ft.judge(checked(0, 0.0), false, 3.0, PumpEdgeVerdict::step));
  CHECK(ft.status().verdict == CalibrationVerdict::withdrawn);
  // GIVEN a calibration of the pickoff map only: a step is not its doing
  CalibrationGuard pickoff(kMinMisfit, kMaxMisfit);
  pickoff.applied(CalibrationSource::file, 7, false, false, 0.0, {}, false);
  CHECK_FALSE(pickoff.judge(checked(0, 0.0), false, 3.0, PumpEdgeVerdict::step));
  CHECK(pickoff.status().verdict == CalibrationVerdict::on_trial);
  // ... and it is confirmed by its check window alone.
  CHECK_FALSE(pickoff.judge(checked(1, 1.0), true, 100.0, PumpEdgeVerdict::step));
  CHECK_FALSE(pickoff.judge(checked(2, 1.0), true, 120.0, PumpEdgeVerdict::step));
  CHECK(pickoff.status().verdict == CalibrationVerdict::confirmed);
}

TEST(CalibrationGuard, AWithdrawalByTheFirmwareIsReportedAndNotJudgedAgain) {
  // GIVEN an online round on trial, then the map before it put back (the
  // identity)
  CalibrationGuard g(kMinMisfit, kMaxMisfit);
  g.applied(CalibrationSource::online, 11, false, 100.0, checked(5, 1.0), true);
  g.applied(CalibrationSource::online, 0, true, 190.0, checked(6, 1.0), true);
  // WHEN the firmware reports the round withdrawn
  g.withdrawn(CalibrationSource::online, 11, 190.0);
  // THEN it is the verdict (HRG_STATUS cal_withdrawn, report.json) with the
  // round's CRC, counted, and no later window judges anything
  CHECK(g.status().verdict == CalibrationVerdict::withdrawn);
  CHECK(g.status().source == CalibrationSource::online);
  CHECK_EQUAL(11u, g.status().crc32);
  DOUBLES_EQUAL(190.0, g.status().judged_s, 0.0);
  CHECK_EQUAL(1u, g.status().withdrawals);
  CHECK_FALSE(g.judge(checked(7, 90.0), true, 200.0));
  CHECK(g.status().verdict == CalibrationVerdict::withdrawn);
}
