// SPDX-License-Identifier: MIT
#pragma once

// Do no harm for a calibration: one put in force (a file, the online
// self-calibration, a CAN block) is on trial until the firmware's own model
// check has judged it. The first check window after it (the campaign's own
// windows prove nothing) must be consistent with the noise (misfit at most
// the gyro's max_window_misfit) or, when a check was made before it was
// applied, not worse than that one. A window far quieter than the model's
// own residual (misfit below min_window_misfit: the model took structure
// for noise, and the gyro withdraws its drift model) has no power to judge:
// the calibration stays on trial until a window that has. A calibration
// with a feedthrough part is also judged by the switch-off steps of the
// corrected signal (PumpEdgeCheck, which free-decay windows cannot see):
// confirmed only once they are consistent, withdrawn (on trial or
// confirmed) as soon as they show a step. Otherwise it is withdrawn (the
// chain goes back to no correction) and the firmware says so.

#include <cstdint>

#include "firmware/estimator_health.hpp"
#include "firmware/pump_edge_check.hpp"

namespace hrg::fw::app {

enum class CalibrationSource : uint8_t {
  none,    // no calibration (the identity)
  file,    // given at start: a file, or the built-in constant on bare metal
  online,  // the firmware's own pickoff self-calibration
  can,     // a CAN calibration block
};
const char* to_string(CalibrationSource s);

enum class CalibrationVerdict : uint8_t {
  none,       // nothing to judge (the identity is in force)
  on_trial,   // in force, no check window has judged it yet
  confirmed,  // a check window agreed
  withdrawn,  // a check window disagreed: taken out of the chain
};
const char* to_string(CalibrationVerdict v);

struct CalibrationStatus {
  CalibrationSource source = CalibrationSource::none;
  CalibrationVerdict verdict = CalibrationVerdict::none;
  uint32_t crc32 = 0;          // of the calibration judged (calibration_crc)
  double applied_s = 0.0;      // time it was put in force
  double misfit_before = 0.0;  // last check misfit before it (0: no check before)
  double misfit_after = 0.0;   // the check that judged it
  double judged_s = 0.0;       // time of that check
  bool feedthrough = false;    // it has a feedthrough part (the switch-off steps judge it too)
  bool window_agreed = false;  // a check window agreed with it
  // The switch-off step check at the verdict (a withdrawal by a step: `step`).
  PumpEdgeVerdict edge = PumpEdgeVerdict::unknown;
  uint32_t withdrawals = 0;  // calibrations withdrawn since start
  // The resonator model's damping part (est::DampingModelCheck), judged on
  // every window while in force: refuted when its terms fit the decays
  // significantly worse than none; the seed's model is then used.
  bool damping_model = false;    // the calibration in force has one
  bool damping_refuted = false;  // it was refuted (and taken out)
  double damping_factor = 0.0;   // how much of its damping change the windows show (1: all)
  double damping_factor_sigma = 0.0;
  double damping_refuted_s = 0.0;
  // The gap harmonic disagreed with the online fit of the pump's drift
  // (est::Estimator::known_gap_refuted): taken out, the online fit used.
  bool gap_refuted = false;
  double gap_refuted_s = 0.0;
};

class CalibrationGuard {
 public:
  CalibrationGuard(double min_misfit, double max_misfit)
      : min_misfit_(min_misfit), max_misfit_(max_misfit) {}

  // A calibration is now in force (`identity`: nothing to judge). `h` is the
  // estimator's health at that instant, `checking`: its check windows count
  // (the campaign is over).
  // `feedthrough`: it changes the feedthrough removal.
  // `damping_model`: it has a damping part (thermal or nonlinear damping).
  void applied(CalibrationSource source, uint32_t crc32, bool identity, bool feedthrough,
               double t_s, const EstimatorHealth& h, bool checking, bool damping_model = false);
  // Once per frame, with the switch-off step check's verdict (reset when the
  // calibration was applied). True when the calibration in force must be
  // withdrawn now.
  bool judge(const EstimatorHealth& h, bool checking, double t_s, PumpEdgeVerdict edge);
  // Without a feedthrough part and a step check.
  void applied(CalibrationSource source, uint32_t crc32, bool identity, double t_s,
               const EstimatorHealth& h, bool checking) {
    applied(source, crc32, identity, false, t_s, h, checking);
  }
  bool judge(const EstimatorHealth& h, bool checking, double t_s) {
    return judge(h, checking, t_s, PumpEdgeVerdict::unknown);
  }
  // The damping model check's latest result while the calibration's damping
  // part is in force: true when it must be taken out now (once).
  bool judge_damping_model(double factor, double factor_sigma, bool refuted, double t_s);
  // The estimator has refuted the calibration's gap harmonic: true once.
  bool judge_gap(bool refuted, double t_s);
  // The firmware has taken a calibration out for a reason of its own (the
  // online self-calibration's rounds, their model refuted) and put back (the
  // parts of) the map in force before it, which is not judged again:
  // reported as the `source` calibration `crc32` withdrawn at t_s.
  void withdrawn(CalibrationSource source, uint32_t crc32, double t_s);

  const CalibrationStatus& status() const { return status_; }

 private:
  double min_misfit_;
  double max_misfit_;
  CalibrationStatus status_{};
  bool withdraw(double t_s);
  uint32_t checks_seen_ = 0;
  bool was_checking_ = false;
};

}  // namespace hrg::fw::app
