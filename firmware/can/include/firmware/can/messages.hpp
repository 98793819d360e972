// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/can/signal.hpp"

namespace hrg::fw::can {

// The HRG CAN protocol (classic CAN, 1 Mbit/s, 11-bit identifiers). The same
// layout is written in firmware/can/hrg.dbc; tests/tools/test_can_dbc.cpp parses
// the DBC and checks that every message and signal below agrees with it.
//
// Identifiers: host commands 0x080-0x08F (highest priority), the command reply
// 0x090, the calibration service 0x0A0-0x0A8, the test bench's LAB_TABLE 0x0C0,
// telemetry 0x100-0x10E. Every telemetry message and the reply carry a
// rolling 8-bit `seq` that increments per message sent, so a reader counts
// losses per message. Commands carry a 4-bit `counter` and a CRC-8 (see
// command.hpp).

// 2: HRG_WAVE_X/Y against the fixed reference of HRG_REFERENCE, HRG_ROW.
// 3: HRG_CAL_READINGS, the firmware's own readings for a calibration file (a
//    log of protocol 3 without them holds none, one of 2 cannot).
// 4: why the compensation is not valid (HRG_STATUS.comp_reasons, DLC 7 -> 8)
//    and the model check against the readout's pattern
//    (HRG_EST_QUALITY.readout_damping_sigmas).
// 5: HRG_CAL_READINGS pages 7-9, the pickoff self-calibration's whole map
//    (a set of 10 pages; a log of protocol 4 is decoded with its own DBC).
inline constexpr uint8_t kProtocolVersion = 5;
inline constexpr uint32_t kBitrateBps = 1'000'000;

// Telemetry messages, in table order (index into kTelemetry).
enum class Tm : uint8_t {
  wave_x,
  wave_y,
  angle,
  loops,
  pump,
  status,
  est_damping,
  est_split,
  est_quality,
  exec,
  info,
  can_stats,
  row,
  reference,
  cal_readings,
};
inline constexpr std::size_t kTelemetryCount = 15;

// HRG_CAL_READINGS is multiplexed: one page per frame, pages 0 to
// kCalReadingsPages - 1 in turn, all of one set from the same readings.
inline constexpr uint8_t kCalReadingsPages = 10;

// Host commands, in table order (index into kCommands); id = 0x080 + index.
enum class Cmd : uint8_t { set_mode, ident, window, agc, status_request };
inline constexpr std::size_t kCommandCount = 5;
inline constexpr uint32_t kCommandIdFirst = 0x080;
inline constexpr uint32_t kCommandIdLast =
    0x08F;  // the whole range is ours: unknown ids get a reply
inline constexpr uint32_t kReplyId = 0x090;

// Calibration service (calibration_transfer.hpp): host frames 0x0A0-0x0A4
// (seed request, key, start, data, end) and the reply 0x0A8, in that order.
inline constexpr std::size_t kCalibrationMessageCount = 6;

extern const std::array<MessageDef, kTelemetryCount> kTelemetry;
extern const std::array<MessageDef, kCommandCount> kCommands;
extern const MessageDef kReply;
// LAB_TABLE: the rate table's input rate and the chamber's temperature as the
// test bench puts them on the bus (`hrg sim --can-log` writes one per
// recording row); the gyro neither sends nor reads it, `hrg can-decode` does.
inline constexpr uint32_t kLabTableId = 0x0C0;
extern const MessageDef kLabTable;
extern const std::array<MessageDef, kCalibrationMessageCount> kCalibrationMessages;

constexpr const MessageDef& telemetry_def(Tm m) { return kTelemetry[static_cast<std::size_t>(m)]; }

// All messages of the protocol (telemetry, commands, reply), or nullptr.
const MessageDef* find_message(uint32_t id);
// Signal of a message by name, or nullptr.
const SignalDef* find_signal(const MessageDef& m, const char* name);

// Signal indexes, in each message's table order.
namespace sig {
enum WaveX : uint8_t { cx_v, sx_v, wave_x_seq, exc };
enum WaveY : uint8_t { cy_v, sy_v, wave_y_seq };
enum Angle : uint8_t { theta_a_rad, output_angle_rad, angle_seq };
enum Loops : uint8_t { pll_freq_hz, quad_effort, loops_seq, pll_locked };
enum Pump : uint8_t { pump_v, pump_phase_rad, agc_setpoint_v, pump_seq };
enum Status : uint8_t {
  mode,
  exc_on,
  exc_line,
  fault_input,
  ident_active,
  comp_valid,
  cal_withdrawn,
  cal_damping_refuted,
  cal_gap_refuted,
  faults,
  temp_c,
  status_seq,
  comp_reasons
};
enum EstDamping : uint8_t { nu_per_s, dnu_c_per_s, dnu_s_per_s, est_damping_seq };
enum EstSplit : uint8_t { dw_c_rad_s, dw_s_rad_s, est_split_seq };
enum EstQuality : uint8_t {
  cond_log10,
  coverage,
  windows,
  est_valid,
  est_quality_seq,
  readout_damping_sigmas
};
enum Exec : uint8_t { overruns, missed_ticks, max_frame_us, cpu_load_pct, exec_seq };
enum Info : uint8_t { protocol_version, angular_gain, window_period_s, window_length_s, info_seq };
enum CanStats : uint8_t {
  tx_queue_full,
  error_frames,
  bus_off_events,
  restarts,
  can_state,
  can_stats_seq
};
enum Row : uint8_t { row_t_s, row_pump_v, row_seq, row_exc };
enum Reference : uint8_t { f_ref_hz, reference_seq };
enum CalReadings : uint8_t {
  readings_page,
  thermal_valid,
  readings_seq,
  pump_edge_edges,
  pump_edge_in_force_s,
  pump_edge_x_re,
  pump_edge_x_im,
  pump_edge_y_re,
  pump_edge_y_im,
  pump_edge_sigma,
  pump_edge_scatter,
  pump_edge_in_force_x_re,
  pump_edge_in_force_x_im,
  pump_edge_in_force_y_re,
  pump_edge_in_force_y_im,
  thermal_damping_per_c,
  thermal_damping_sigma_per_c,
  self_cal_valid,
  self_cal_gain,
  self_cal_gain_sigma,
  self_cal_misalignment,
  self_cal_misalignment_sigma,
  self_cal_phase,
  self_cal_phase_sigma
};
enum LabTable : uint8_t { table_rate_dps, table_temp_c, table_seq };
enum SetMode : uint8_t { target_mode, set_mode_counter, set_mode_crc };
enum Ident : uint8_t { action, ident_counter, ident_crc };
enum Window : uint8_t { period_s, length_s, window_counter, window_crc };
enum Agc : uint8_t { setpoint_v, agc_counter, agc_crc };
enum StatusRequest : uint8_t { status_request_counter, status_request_crc };
enum Reply : uint8_t { command_id, reply_counter, result, detail, reply_seq };
}  // namespace sig

// Fixed field positions shared by every message of a kind.
inline constexpr uint8_t kSeqBits = 8;
inline constexpr uint8_t kCounterBits = 4;

}  // namespace hrg::fw::can
