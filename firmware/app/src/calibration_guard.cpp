// SPDX-License-Identifier: MIT
#include "firmware/app/calibration_guard.hpp"

namespace hrg::fw::app {

const char* to_string(CalibrationSource s) {
  switch (s) {
    case CalibrationSource::none: return "none";
    case CalibrationSource::file: return "file";
    case CalibrationSource::online: return "online";
    case CalibrationSource::can: return "can";
  }
  return "?";
}

const char* to_string(CalibrationVerdict v) {
  switch (v) {
    case CalibrationVerdict::none: return "none";
    case CalibrationVerdict::on_trial: return "on_trial";
    case CalibrationVerdict::confirmed: return "confirmed";
    case CalibrationVerdict::withdrawn: return "withdrawn";
  }
  return "?";
}

void CalibrationGuard::applied(CalibrationSource source, uint32_t crc32, bool identity,
                               bool feedthrough, double t_s, const EstimatorHealth& h,
                               bool checking, bool damping_model) {
  const uint32_t withdrawals = status_.withdrawals;
  status_ = CalibrationStatus{};
  status_.withdrawals = withdrawals;
  status_.source = identity ? CalibrationSource::none : source;
  status_.verdict = identity ? CalibrationVerdict::none : CalibrationVerdict::on_trial;
  status_.crc32 = crc32;
  status_.applied_s = t_s;
  status_.feedthrough = !identity && feedthrough;
  status_.damping_model = damping_model;
  // A check made before (with the previous correction) is the reference
  // the new one must not be worse than.
  status_.misfit_before = checking && h.windows_checked > 0 ? h.window_misfit : 0.0;
  checks_seen_ = h.windows_checked;
  was_checking_ = checking;
}

bool CalibrationGuard::withdraw(double t_s) {
  status_.verdict = CalibrationVerdict::withdrawn;
  status_.judged_s = t_s;
  ++status_.withdrawals;
  return true;
}

void CalibrationGuard::withdrawn(CalibrationSource source, uint32_t crc32, double t_s) {
  status_.source = source;
  status_.crc32 = crc32;
  withdraw(t_s);
}

bool CalibrationGuard::judge(const EstimatorHealth& h, bool checking, double t_s,
                             PumpEdgeVerdict edge) {
  const bool in_force = status_.verdict == CalibrationVerdict::on_trial ||
                        status_.verdict == CalibrationVerdict::confirmed;
  if (!in_force) return false;
  status_.edge = edge;
  // A step at the switch-offs is evidence at any time (no model involved).
  if (status_.feedthrough && edge == PumpEdgeVerdict::step) return withdraw(t_s);
  if (status_.verdict != CalibrationVerdict::on_trial) return false;
  const bool edge_ok = !status_.feedthrough || edge == PumpEdgeVerdict::consistent;
  // Windows checked while the campaign runs (against an early model) or
  // the one that ends it are no verdict: count from the campaign's end.
  if (!status_.window_agreed) {
    if (!checking || !was_checking_) {
      checks_seen_ = h.windows_checked;
      was_checking_ = checking;
      return false;
    }
    if (h.windows_checked == checks_seen_) return false;
    checks_seen_ = h.windows_checked;
    const double m = h.window_misfit;
    status_.misfit_after = m;
    status_.judged_s = t_s;
    if (m < min_misfit_) return false;  // no power to judge: stays on trial
    const bool noise_like = m <= max_misfit_;
    const bool not_worse = status_.misfit_before > 0.0 && m <= status_.misfit_before;
    if (!(noise_like || not_worse)) return withdraw(t_s);
    status_.window_agreed = true;
  }
  if (edge_ok) status_.verdict = CalibrationVerdict::confirmed;
  return false;
}

bool CalibrationGuard::judge_damping_model(double factor, double factor_sigma, bool refuted,
                                           double t_s) {
  if (!status_.damping_model || status_.damping_refuted) return false;
  status_.damping_factor = factor;
  status_.damping_factor_sigma = factor_sigma;
  if (!refuted) return false;
  status_.damping_refuted = true;
  status_.damping_refuted_s = t_s;
  return true;
}

bool CalibrationGuard::judge_gap(bool refuted, double t_s) {
  if (!refuted || status_.gap_refuted) return false;
  status_.gap_refuted = true;
  status_.gap_refuted_s = t_s;
  return true;
}

}  // namespace hrg::fw::app
