// SPDX-License-Identifier: MIT
#include "firmware/can/messages.hpp"

namespace hrg::fw::can {

namespace {

// Raw limits of common field widths, as physical values.
constexpr double kS24 = 8388608.0;  // 2^23
constexpr double kS16 = 32768.0;    // 2^15

// clang-format off
// name, start, len, signed, factor, offset, min, max, unit
constexpr SignalDef kWaveX[] = {
  {"cx_v", 0, 24, true, 1e-6, 0, -kS24 * 1e-6, (kS24 - 1) * 1e-6, "V"},
  {"sx_v", 24, 24, true, 1e-6, 0, -kS24 * 1e-6, (kS24 - 1) * 1e-6, "V"},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
  {"exc", 56, 1, false, 1, 0, 0, 1, ""},
};
constexpr SignalDef kWaveY[] = {
  {"cy_v", 0, 24, true, 1e-6, 0, -kS24 * 1e-6, (kS24 - 1) * 1e-6, "V"},
  {"sy_v", 24, 24, true, 1e-6, 0, -kS24 * 1e-6, (kS24 - 1) * 1e-6, "V"},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kAngle[] = {
  {"theta_a_rad", 0, 16, true, 1e-4, 0, -kS16 * 1e-4, (kS16 - 1) * 1e-4, "rad"},
  {"output_angle_rad", 16, 32, true, 1e-7, 0, -2147483648.0 * 1e-7, 2147483647.0 * 1e-7, "rad"},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kLoops[] = {
  {"pll_freq_hz", 0, 32, false, 1e-5, 0, 0, 4294967295.0 * 1e-5, "Hz"},
  {"quad_effort", 32, 16, true, 1e-4, 0, -1, 1, ""},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
  {"pll_locked", 56, 1, false, 1, 0, 0, 1, ""},
};
constexpr SignalDef kPump[] = {
  {"pump_v", 0, 16, false, 1e-3, 0, 0, 65.535, "V"},
  {"pump_phase_rad", 16, 16, true, 1e-4, 0, -3.1416, 3.1416, "rad"},
  {"agc_setpoint_v", 32, 16, false, 1e-4, 0, 0, 6.5535, "V"},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kStatus[] = {
  {"mode", 0, 8, false, 1, 0, 0, 7, ""},
  {"exc_on", 8, 1, false, 1, 0, 0, 1, ""},
  {"exc_line", 9, 1, false, 1, 0, 0, 1, ""},
  {"fault_input", 10, 1, false, 1, 0, 0, 1, ""},
  {"ident_active", 11, 1, false, 1, 0, 0, 1, ""},
  {"comp_valid", 12, 1, false, 1, 0, 0, 1, ""},
  {"cal_withdrawn", 13, 1, false, 1, 0, 0, 1, ""},
  {"cal_damping_refuted", 14, 1, false, 1, 0, 0, 1, ""},
  {"cal_gap_refuted", 15, 1, false, 1, 0, 0, 1, ""},
  {"faults", 16, 16, false, 1, 0, 0, 65535, ""},
  {"temp_c", 32, 16, true, 0.01, 0, -327.68, 327.67, "degC"},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
  // fw::CompensationReason bits (compensation_reason.hpp): all 8 used.
  {"comp_reasons", 56, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kEstDamping[] = {
  {"nu_per_s", 0, 24, false, 1e-8, 0, 0, 16777215.0 * 1e-8, "1/s"},
  {"dnu_c_per_s", 24, 16, true, 1e-7, 0, -kS16 * 1e-7, (kS16 - 1) * 1e-7, "1/s"},
  {"dnu_s_per_s", 40, 16, true, 1e-7, 0, -kS16 * 1e-7, (kS16 - 1) * 1e-7, "1/s"},
  {"seq", 56, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kEstSplit[] = {
  {"dw_c_rad_s", 0, 24, true, 1e-8, 0, -kS24 * 1e-8, (kS24 - 1) * 1e-8, "rad/s"},
  {"dw_s_rad_s", 24, 24, true, 1e-8, 0, -kS24 * 1e-8, (kS24 - 1) * 1e-8, "rad/s"},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kEstQuality[] = {
  {"cond_log10", 0, 16, false, 1e-3, 0, 0, 65.535, ""},
  {"coverage", 16, 16, false, 1e-4, 0, 0, 1, ""},
  {"windows", 32, 16, false, 1, 0, 0, 65535, ""},
  {"valid", 48, 1, false, 1, 0, 0, 1, ""},
  {"seq", 56, 8, false, 1, 0, 0, 255, ""},
  // Standard errors (the firmware's limit is 5): 0.5 resolution, saturates at 63.5.
  {"readout_damping_sigmas", 49, 7, false, 0.5, 0, 0, 63.5, ""},
};
constexpr SignalDef kExec[] = {
  {"overruns", 0, 16, false, 1, 0, 0, 65535, ""},
  {"missed_ticks", 16, 16, false, 1, 0, 0, 65535, ""},
  {"max_frame_us", 32, 16, false, 1, 0, 0, 65535, "us"},
  {"cpu_load_pct", 48, 8, false, 0.5, 0, 0, 127.5, "%"},
  {"seq", 56, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kInfo[] = {
  {"protocol_version", 0, 8, false, 1, 0, 0, 255, ""},
  {"angular_gain", 8, 16, false, 1e-5, 0, 0, 0.65535, ""},
  {"window_period_s", 24, 16, false, 0.1, 0, 0, 6553.5, "s"},
  {"window_length_s", 40, 16, false, 1e-3, 0, 0, 65.535, "s"},
  {"seq", 56, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kCanStats[] = {
  {"tx_queue_full", 0, 16, false, 1, 0, 0, 65535, ""},
  {"error_frames", 16, 16, false, 1, 0, 0, 65535, ""},
  {"bus_off_events", 32, 8, false, 1, 0, 0, 255, ""},
  {"restarts", 40, 8, false, 1, 0, 0, 255, ""},
  {"can_state", 48, 2, false, 1, 0, 0, 3, ""},
  {"seq", 56, 8, false, 1, 0, 0, 255, ""},
};

// One row of an audit-grade recording (see telemetry.hpp, EnvelopeReference):
// the envelope's time and the drive state as applied, with the pump at the
// same block; rows pair with HRG_WAVE_X/HRG_WAVE_Y by `seq`.
constexpr SignalDef kRow[] = {
  {"t_s", 0, 32, false, 1e-4, 0, 0, 4294967295.0 * 1e-4, "s"},
  {"pump_v", 32, 16, false, 1e-3, 0, 0, 65.535, "V"},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
  {"exc", 56, 1, false, 1, 0, 0, 1, ""},
};
constexpr SignalDef kReference[] = {
  {"f_ref_hz", 0, 32, false, 1e-5, 0, 0, 4294967295.0 * 1e-5, "Hz"},
  {"seq", 32, 8, false, 1, 0, 0, 255, ""},
};
// The firmware's own readings for a calibration file (FirmwareEstimates),
// one page per frame after the multiplexor. Feedthrough parts: 2e-8 V/V
// (1/50 of the check's sigma, ~1e-6), +-0.168 V/V (the calibration's range
// is +-0.1); their sigmas 1e-9 V/V up to 0.0168 (a reading less precise
// than that weighs nothing against the audit's); thermal damping 1e-7
// /degC (1/1000 of its sigma, ~1e-4), +-0.839 (the calibration's +-0.2).
constexpr double kFtFactor = 2e-8;
constexpr double kSigmaFactor = 1e-9;
constexpr double kU24 = 16777215.0;  // 2^24 - 1
// A feedthrough part (signed, 24 bits) and a sigma (unsigned, 24 bits) of a page.
constexpr SignalDef ft(const char* name, uint8_t start, uint8_t page) {
  return {name, start, 24, true, kFtFactor, 0, -kS24 * kFtFactor, (kS24 - 1) * kFtFactor, "V/V",
          MuxRole::multiplexed, page};
}
constexpr SignalDef ft_sigma(const char* name, uint8_t start) {
  return {name, start, 24, false, kSigmaFactor, 0, 0, kU24 * kSigmaFactor, "V/V",
          MuxRole::multiplexed, 3};
}
// The pickoff map's parts (-, rad): 4e-9 (1/150 of the gain's sigma at
// 1800 s, ~6e-7), +-0.537 (the calibration's ranges: gain +-0.2,
// misalignment +-0.175 rad, phase +-0.349 rad); their sigmas 2e-9 up to
// 2.1e-3 (saturates: a reading that imprecise weighs nothing against the
// audit's, gain ~7e-5, misalignment ~9e-6 rad at 365 s).
constexpr double kMapFactor = 4e-9;
constexpr double kMapSigmaFactor = 2e-9;
constexpr double kS28 = 134217728.0;  // 2^27
constexpr double kU20 = 1048575.0;    // 2^20 - 1
constexpr SignalDef map_part(const char* name, const char* unit, uint8_t page) {
  return {name, 8, 28, true, kMapFactor, 0, -kS28 * kMapFactor, (kS28 - 1) * kMapFactor, unit,
          MuxRole::multiplexed, page};
}
constexpr SignalDef map_sigma(const char* name, const char* unit, uint8_t page) {
  return {name, 36, 20, false, kMapSigmaFactor, 0, 0, kU20 * kMapSigmaFactor, unit,
          MuxRole::multiplexed, page};
}
constexpr auto kMux = MuxRole::multiplexed;
constexpr SignalDef kCalReadings[] = {
  {"page", 0, 4, false, 1, 0, 0, kCalReadingsPages - 1, "", MuxRole::multiplexor},
  {"thermal_valid", 4, 1, false, 1, 0, 0, 1, ""},
  {"seq", 56, 8, false, 1, 0, 0, 255, ""},
  {"pump_edge_edges", 8, 16, false, 1, 0, 0, 65535, "", kMux, 0},
  {"pump_edge_in_force_s", 24, 32, false, 0.01, 0, 0, 4294967295.0 * 0.01, "s", kMux, 0},
  ft("pump_edge_x_re_v_per_v", 8, 1),
  ft("pump_edge_x_im_v_per_v", 32, 1),
  ft("pump_edge_y_re_v_per_v", 8, 2),
  ft("pump_edge_y_im_v_per_v", 32, 2),
  ft_sigma("pump_edge_sigma_v_per_v", 8),
  ft_sigma("pump_edge_scatter_v_per_v", 32),
  ft("pump_edge_in_force_x_re_v_per_v", 8, 4),
  ft("pump_edge_in_force_x_im_v_per_v", 32, 4),
  ft("pump_edge_in_force_y_re_v_per_v", 8, 5),
  ft("pump_edge_in_force_y_im_v_per_v", 32, 5),
  {"thermal_damping_per_c", 8, 24, true, 1e-7, 0, -kS24 * 1e-7, (kS24 - 1) * 1e-7, "1/degC",
   kMux, 6},
  {"thermal_damping_sigma_per_c", 32, 24, false, 1e-8, 0, 0, kU24 * 1e-8, "1/degC", kMux, 6},
  {"self_cal_valid", 5, 1, false, 1, 0, 0, 1, ""},
  map_part("self_cal_gain", "", 7),
  map_sigma("self_cal_gain_sigma", "", 7),
  map_part("self_cal_misalignment_rad", "rad", 8),
  map_sigma("self_cal_misalignment_sigma_rad", "rad", 8),
  map_part("self_cal_phase_rad", "rad", 9),
  map_sigma("self_cal_phase_sigma_rad", "rad", 9),
};
// The test bench's rate table and thermal chamber (not the gyro).
constexpr SignalDef kLabTableSignals[] = {
  {"rate_dps", 0, 32, true, 1e-6, 0, -2147483648.0 * 1e-6, 2147483647.0 * 1e-6, "deg/s"},
  {"temp_c", 32, 16, true, 0.01, 0, -327.68, 327.67, "degC"},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
};

// Commands: [payload..., counter (4 bits) + 4 reserved zero bits, CRC-8].
constexpr SignalDef kSetMode[] = {
  {"mode", 0, 8, false, 1, 0, 0, 7, ""},
  {"counter", 8, 4, false, 1, 0, 0, 15, ""},
  {"crc", 16, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kIdent[] = {
  {"action", 0, 8, false, 1, 0, 0, 1, ""},
  {"counter", 8, 4, false, 1, 0, 0, 15, ""},
  {"crc", 16, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kWindow[] = {
  {"period_s", 0, 16, false, 0.1, 0, 1, 3600, "s"},
  {"length_s", 16, 16, false, 1e-3, 0, 0.01, 5, "s"},
  {"counter", 32, 4, false, 1, 0, 0, 15, ""},
  {"crc", 40, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kAgc[] = {
  {"setpoint_v", 0, 16, false, 1e-4, 0, 0.05, 2, "V"},
  {"counter", 16, 4, false, 1, 0, 0, 15, ""},
  {"crc", 24, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kStatusRequest[] = {
  {"counter", 0, 4, false, 1, 0, 0, 15, ""},
  {"crc", 8, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kReplySignals[] = {
  {"command_id", 0, 8, false, 1, 0, 0, 255, ""},
  {"counter", 8, 4, false, 1, 0, 0, 15, ""},
  {"result", 12, 4, false, 1, 0, 0, 15, ""},
  {"detail", 16, 8, false, 1, 0, 0, 255, ""},
  {"seq", 24, 8, false, 1, 0, 0, 255, ""},
};
// Calibration service: control frames end with the commands' CRC-8; data
// frames carry a sequence number and 7 bytes of the block (little-endian).
constexpr SignalDef kCalSeedRequest[] = {
  {"crc", 0, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kCalKey[] = {
  {"key", 0, 32, false, 1, 0, 0, 4294967295.0, ""},
  {"crc", 32, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kCalStart[] = {
  {"length", 0, 16, false, 1, 0, 0, 65535, "B"},
  {"block_crc", 16, 32, false, 1, 0, 0, 4294967295.0, ""},
  {"crc", 48, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kCalData[] = {
  {"seq", 0, 8, false, 1, 0, 0, 255, ""},
  {"data_lo", 8, 32, false, 1, 0, 0, 4294967295.0, ""},
  {"data_hi", 40, 24, false, 1, 0, 0, 16777215, ""},
};
constexpr SignalDef kCalEnd[] = {
  {"crc", 0, 8, false, 1, 0, 0, 255, ""},
};
constexpr SignalDef kCalReply[] = {
  {"step", 0, 4, false, 1, 0, 0, 15, ""},
  {"result", 4, 4, false, 1, 0, 0, 15, ""},
  {"detail", 8, 8, false, 1, 0, 0, 255, ""},
  {"value", 16, 32, false, 1, 0, 0, 4294967295.0, ""},
  {"seq", 48, 8, false, 1, 0, 0, 255, ""},
};
// clang-format on

constexpr bool fits(std::span<const SignalDef> sigs, uint8_t dlc) {
  for (const auto& s : sigs) {
    if (s.length == 0 || s.length > 32 || s.start_bit + s.length > 8u * dlc) return false;
  }
  return true;
}

// No two signals present on the same page share a bit; a multiplexed
// signal's page is one the multiplexor can hold.
constexpr bool disjoint(std::span<const SignalDef> sigs) {
  for (std::size_t i = 0; i < sigs.size(); ++i) {
    for (std::size_t j = i + 1; j < sigs.size(); ++j) {
      const SignalDef& a = sigs[i];
      const SignalDef& b = sigs[j];
      const bool both = a.mux != MuxRole::multiplexed || b.mux != MuxRole::multiplexed ||
                        a.mux_value == b.mux_value;
      if (both && a.start_bit < b.start_bit + b.length && b.start_bit < a.start_bit + a.length) {
        return false;
      }
    }
    if (sigs[i].mux == MuxRole::multiplexed && sigs[i].mux_value >= kCalReadingsPages) return false;
  }
  return true;
}

}  // namespace

// clang-format off
const std::array<MessageDef, kTelemetryCount> kTelemetry = {{
  {"HRG_WAVE_X",      0x100, 8, 100, "HRG", kWaveX},
  {"HRG_WAVE_Y",      0x101, 8, 100, "HRG", kWaveY},
  {"HRG_ANGLE",       0x102, 7, 500, "HRG", kAngle},
  {"HRG_LOOPS",       0x103, 8, 100, "HRG", kLoops},
  {"HRG_PUMP",        0x104, 7, 100, "HRG", kPump},
  {"HRG_STATUS",      0x105, 8,  10, "HRG", kStatus},
  {"HRG_EST_DAMPING", 0x106, 8,   2, "HRG", kEstDamping},
  {"HRG_EST_SPLIT",   0x107, 7,   2, "HRG", kEstSplit},
  {"HRG_EST_QUALITY", 0x108, 8,   2, "HRG", kEstQuality},
  {"HRG_EXEC",        0x109, 8,  10, "HRG", kExec},
  {"HRG_INFO",        0x10A, 8,   1, "HRG", kInfo},
  {"HRG_CAN_STATS",   0x10B, 8,   1, "HRG", kCanStats},
  {"HRG_ROW",         0x10C, 8, 100, "HRG", kRow},
  {"HRG_REFERENCE",   0x10D, 5,   1, "HRG", kReference},
  {"HRG_CAL_READINGS",0x10E, 8,  10, "HRG", kCalReadings},
}};

const MessageDef kLabTable = {"LAB_TABLE", kLabTableId, 7, 0, "LAB", kLabTableSignals};

const std::array<MessageDef, kCommandCount> kCommands = {{
  {"HOST_SET_MODE",       0x080, 3, 0, "HOST", kSetMode},
  {"HOST_IDENT",          0x081, 3, 0, "HOST", kIdent},
  {"HOST_WINDOW",         0x082, 6, 0, "HOST", kWindow},
  {"HOST_AGC",            0x083, 4, 0, "HOST", kAgc},
  {"HOST_STATUS_REQUEST", 0x084, 2, 0, "HOST", kStatusRequest},
}};

const MessageDef kReply = {"HRG_CMD_REPLY", kReplyId, 4, 0, "HRG", kReplySignals};

const std::array<MessageDef, kCalibrationMessageCount> kCalibrationMessages = {{
  {"HOST_CAL_SEED_REQUEST", 0x0A0, 1, 0, "HOST", kCalSeedRequest},
  {"HOST_CAL_KEY",          0x0A1, 5, 0, "HOST", kCalKey},
  {"HOST_CAL_START",        0x0A2, 7, 0, "HOST", kCalStart},
  {"HOST_CAL_DATA",         0x0A3, 8, 0, "HOST", kCalData},
  {"HOST_CAL_END",          0x0A4, 1, 0, "HOST", kCalEnd},
  {"HRG_CAL_REPLY",         0x0A8, 7, 0, "HRG",  kCalReply},
}};
// clang-format on

static_assert(fits(kWaveX, 8) && fits(kWaveY, 8) && fits(kAngle, 7) && fits(kLoops, 8) &&
              fits(kPump, 7) && fits(kStatus, 8) && fits(kEstDamping, 8) && fits(kEstSplit, 7) &&
              fits(kEstQuality, 8) && fits(kExec, 8) && fits(kInfo, 8) && fits(kCanStats, 8) &&
              fits(kRow, 8) && fits(kReference, 5) && fits(kLabTableSignals, 7) &&
              fits(kCalReadings, 8));
static_assert(disjoint(kStatus) && disjoint(kEstQuality) && disjoint(kCalReadings));
static_assert(fits(kSetMode, 3) && fits(kIdent, 3) && fits(kWindow, 6) && fits(kAgc, 4) &&
              fits(kStatusRequest, 2) && fits(kReplySignals, 4));
static_assert(fits(kCalSeedRequest, 1) && fits(kCalKey, 5) && fits(kCalStart, 7) &&
              fits(kCalData, 8) && fits(kCalEnd, 1) && fits(kCalReply, 7));

namespace {
bool same(const char* a, const char* b) {
  while (*a != '\0' && *a == *b) {
    ++a;
    ++b;
  }
  return *a == *b;
}
}  // namespace

const MessageDef* find_message(uint32_t id) {
  for (const auto& m : kTelemetry)
    if (m.id == id) return &m;
  for (const auto& m : kCommands)
    if (m.id == id) return &m;
  if (id == kReply.id) return &kReply;
  for (const auto& m : kCalibrationMessages)
    if (m.id == id) return &m;
  if (id == kLabTable.id) return &kLabTable;
  return nullptr;
}

const SignalDef* find_signal(const MessageDef& m, const char* name) {
  for (const auto& s : m.signals)
    if (same(s.name, name)) return &s;
  return nullptr;
}

}  // namespace hrg::fw::can
