// SPDX-License-Identifier: MIT
#pragma once

// `hrg audit REC --calibration OUT.toml`: the audit's accepted findings as the
// firmware's calibration file (firmware/calibration_file.hpp), each value with
// its 1-sigma uncertainty as a `_sigma` key. What the firmware cannot correct
// (or what the audit saw only as an alternative) is listed as a comment with
// the reason; nothing is written as a correction that was not accepted.

#include <numbers>
#include <string>
#include <vector>

#include "audit/audit.hpp"
#include "audit/firmware_estimates.hpp"
#include "firmware/calibration_file.hpp"

namespace hrg::audit {

struct CalibrationWriterOptions {
  // Phase of the pump voltage against the wave in the firmware that made the
  // recording (dsp::ChainConfig::pump_phase_rad). The audit measures the
  // feedthrough against the wave's phase; the firmware removes it per volt
  // of its actual pump envelope: k = c_audit e^{-i pump_phase}.
  double pump_phase_rad = std::numbers::pi / 4.0;
  // The firmware's own estimates from the recording's header
  // (firmware_estimates): where the audit found the same effect, the value
  // written is the two combined (combine_estimates), said in a comment.
  FirmwareEstimates firmware{};
};

struct CalibrationFromAudit {
  fw::CalibrationFile file;
  std::vector<std::string> comments;  // reasons and provenance, one line each
};

// Throws fw::CalibrationFileError when an accepted finding is outside the
// firmware's physical range (the file would be refused on loading).
CalibrationFromAudit calibration_from_audit(const AuditResult& r, const std::string& source,
                                            const CalibrationWriterOptions& opt = {});

void write_calibration_file(const std::string& path, const AuditResult& r,
                            const std::string& source, const CalibrationWriterOptions& opt = {});

}  // namespace hrg::audit
