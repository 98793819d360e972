// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>

namespace hrg::fw {

// Why the drift compensation is not one the firmware stands behind, as a bit
// set (GyroStatus::compensation_reasons, the telemetry's `comp_reasons`
// column, CAN HRG_STATUS.comp_reasons): built in one place, Gyro::
// check_model, with GyroStatus::compensation_valid. Values are stable: they
// go on the bus and into recordings.
enum class CompensationReason : uint8_t {
  none = 0,
  not_in_force = 1u << 0,        // the window campaign has not ended (no model applied yet)
  check_failed = 1u << 1,        // a check window disagreed with the model: withdrawn for good
  not_checked = 1u << 2,         // no check window has agreed with it yet
  pump_edge_step = 1u << 3,      // the corrected signal steps at the pump's switch-offs
  control_drift_lost = 1u << 4,  // a D_Phi once added is no longer added
  readout_in_damping = 1u << 5,  // the model's damping anisotropy is the readout's pattern
  // D_Phi is not valid and not applied: the readout's own 4 theta pattern
  // (a significant pickoff gain or misalignment, or readout_in_damping)
  // explains what its fits read. The compensation is not valid with it only
  // while the pump's part of D_Phi is in use (a measured drift withheld).
  control_drift_withheld = 1u << 6,
  // The pickoff self-identification reads a phase lag the correction in
  // force leaves, whose own drift (2 nu phi, a 4 theta pattern in no model)
  // is more than half the drift the model removes: the compensated output
  // may then be worse than raw.
  readout_phase_drift = 1u << 7,
};
inline constexpr int kCompensationReasonBits = 8;

constexpr uint8_t reason_bit(CompensationReason r) { return static_cast<uint8_t>(r); }

// The bits' names, bit 0 first (reports, recordings' readers).
inline constexpr std::array<const char*, kCompensationReasonBits> kCompensationReasonNames = {
    "not_in_force",           "check_failed",       "not_checked",
    "pump_edge_step",         "control_drift_lost", "readout_in_damping",
    "control_drift_withheld", "readout_phase_drift"};

}  // namespace hrg::fw
