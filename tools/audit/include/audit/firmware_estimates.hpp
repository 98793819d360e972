// SPDX-License-Identifier: MIT
#pragma once

// The firmware's own estimates of what a calibration holds, as a recording's
// header carries them (tools/audit/README.md, "--calibration"), and the one
// rule that combines an estimate of the audit's with the firmware's:
//   - pump_edge_*: the switch-off step check's residual drive feedthrough
//     (fw::PumpEdgeCheck), per channel, per volt of pump, referred to the raw
//     pickoffs, on top of the feedthrough in force while its edges were read
//     (pump_edge_in_force_*);
//   - damping_check_*: the damping model check's thermal damping coefficient
//     (est::DampingModelCheck: its factor times the beta in force);
//   - self_cal_*: the pickoff self-calibration's whole y pickoff map
//     (est::whole_estimate: the map in force composed with the residual its
//     windows read through it), each part with its own 1 sigma.
// A recording without a group's keys has no such estimate; a group with a key
// missing or not a number of its range is refused, naming the key.

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>

#include "recording/recording.hpp"

namespace hrg::audit {

struct FirmwareFeedthrough {
  std::array<double, 4> total_v_per_v{};  // x re, x im, y re, y im: in force + residual
  double sigma_v_per_v = 0.0;             // the larger of the check's sigma and its scatter's
  double check_sigma_v_per_v = 0.0;       // as the check states them
  double scatter_v_per_v = 0.0;
  long edges = 0;
  double in_force_s = 0.0;  // how long the correction the edges saw had been in force
};

struct FirmwareThermalDamping {
  double per_c = 0.0;
  double sigma_per_c = 0.0;
};

// One part of the pickoff map (gain -, misalignment and phase rad, in the
// calibration's convention) and its 1 sigma.
struct FirmwarePickoffPart {
  double value = 0.0;
  double sigma = 0.0;
};

struct FirmwarePickoffMap {
  FirmwarePickoffPart gain;
  FirmwarePickoffPart misalignment_rad;
  FirmwarePickoffPart phase_rad;
};

struct FirmwareEstimates {
  std::optional<FirmwareFeedthrough> feedthrough;
  std::optional<FirmwareThermalDamping> thermal_damping;
  std::optional<FirmwarePickoffMap> pickoff;
};

// Reads the keys of `rec`'s header; throws std::runtime_error naming the
// source and the key when a key of a present group is missing or malformed.
FirmwareEstimates firmware_estimates(const recording::Recording& rec, const std::string& source);

// What combine_estimates did.
enum class CombinedBy { weighted, audit_alone, firmware_alone };

struct CombinedEstimate {
  std::array<double, 4> value{};  // the first `parts` are used
  double sigma = 0.0;
  CombinedBy by = CombinedBy::weighted;
  double disagreement_sigmas = 0.0;  // the largest part's |a - f| / sqrt(sa^2 + sf^2)
};

// Estimates beyond this many sigmas apart are not averaged: the more precise
// one is taken alone.
inline constexpr double kMaxDisagreementSigmas = 5.0;

// Two estimates of the same parts (at most 4), each with one sigma for every
// part: weighted by inverse variance, or, when a part disagrees by more than
// kMaxDisagreementSigmas, the one with the smaller sigma alone.
CombinedEstimate combine_estimates(std::span<const double> audit, double sigma_audit,
                                   std::span<const double> firmware, double sigma_firmware);

// The calibration file's comment on it: what was done and why, with both
// estimates and their sigmas (`what`: the key or effect; `unit` after values).
std::string describe_combination(const std::string& what, std::span<const double> audit,
                                 double sigma_audit, std::span<const double> firmware,
                                 double sigma_firmware, const CombinedEstimate& c,
                                 const std::string& unit);

}  // namespace hrg::audit
