// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>

#include "firmware/can/firmware_estimates.hpp"

namespace hrg::can {

struct CanDecodeOptions {
  std::string log_path;
  std::string out_path;                // .csv or .csv.gz
  std::string dbc_path;                // empty: the repository's firmware/can/hrg.dbc
  std::optional<double> angular_gain;  // overrides HRG_INFO.angular_gain
  std::optional<double> f_ref_hz;      // overrides HRG_REFERENCE.f_ref_hz (lost frames)
};

// Per-message frame counts and losses counted from the rolling `seq`.
struct MessageLosses {
  uint64_t frames = 0;
  uint64_t lost = 0;
};

struct CanDecodeSummary {
  uint64_t frames = 0;          // frames in the log
  uint64_t unknown_frames = 0;  // identifiers not in the DBC (error frames included)
  uint64_t rows = 0;            // recording rows (paired HRG_WAVE_X/HRG_WAVE_Y)
  uint64_t unpaired_wave = 0;   // wave frames whose partner was lost
  std::map<std::string, MessageLosses> messages;  // by DBC message name
  double f_ref_hz = 0;
  double angular_gain = 0;
  double t0_s = 0;             // log time of the first frame
  bool has_lab_table = false;  // LAB_TABLE frames give rate_dps and temp_c
  // The firmware's readings from the last complete HRG_CAL_READINGS set
  // (none: no such set in the log), the complete sets and those dropped
  // for a lost or out-of-turn page.
  std::optional<fw::can::FirmwareEstimates> estimates;
  uint64_t cal_readings_sets = 0;
  uint64_t cal_readings_dropped = 0;
  // Bus load of the log: every frame at its worst-case stuffed length
  // (11-bit identifiers; error frames left out) over the span of the log.
  double bus_bits = 0;
  double span_s = 0;
  unsigned bitrate_bps = 0;  // the DBC's BS_
};

// Turns a candump -l log of HRG telemetry into an hrg-recording v1, decoding
// with the DBC. Rows are the HRG_WAVE_X/HRG_WAVE_Y/HRG_ROW triples (same
// seq): envelopes against the fixed reference of HRG_REFERENCE (metadata
// f_ref_hz) at the firmware's row time, exc the drive as applied, pump_v of
// the same block; rate_dps and temp_c from the latest LAB_TABLE when the log
// has any (else temp_c from HRG_STATUS and no rate); mode, exc_cmd (the
// excitation command) and pll_hz the latest values, and with a DBC of
// protocol 4 the compensation's comp_valid, comp_reasons (HRG_STATUS) and
// readout_damping_sigmas (HRG_EST_QUALITY), the columns hrg sim's
// telemetry.csv has. Losses are counted per
// message from the sequence counters and written to the metadata. The
// firmware's own readings (HRG_CAL_READINGS, last complete set) become the
// header keys hrg sim writes (can/estimates_header.hpp); none without a
// complete set. Throws std::runtime_error (naming file and line) on
// unreadable input, a reading outside its DBC range, or when K or the
// reference frequency is unknown.
CanDecodeSummary can_decode(const CanDecodeOptions& options);

// `hrg can-decode LOG -o REC.csv [--dbc FILE] [--angular-gain K] [--f-ref-hz F]`.
int can_decode_main(std::span<char* const> args);

}  // namespace hrg::can
