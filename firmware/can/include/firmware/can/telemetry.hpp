// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/can/firmware_estimates.hpp"
#include "firmware/can/messages.hpp"
#include "firmware/mode.hpp"
#include "hal/can.hpp"

namespace hrg::fw::can {

// Everything the telemetry reports, in SI units, filled by the firmware once per
// base frame. Values outside a signal's range saturate on the bus; counters
// saturate at their field width.
struct TelemetrySnapshot {
  // Demodulated pickoffs (physics.md section 3) against the fixed reference
  // f_ref_hz at the row time row_t_s (EnvelopeReference): what an
  // hrg-recording holds, so the decoded log needs no phase of ours.
  double cx_v = 0, sx_v = 0, cy_v = 0, sy_v = 0;
  double row_t_s = 0;           // time of the envelope (centre of the demodulator's window)
  bool row_exc = true;          // a drive acted inside the envelope's window (DAC latency included)
  bool row_ready = true;        // false: the envelope has no reference yet (wave and row held back)
  double f_ref_hz = 0;          // the fixed demodulation reference of the recording
  double theta_a_rad = 0;       // pattern angle, (-pi/4, pi/4] or unwrapped
  double output_angle_rad = 0;  // gyro output angle, -2 (theta_A - theta_A0) / K
  double pll_freq_hz = 0;
  bool pll_locked = false;
  double quad_effort = 0;  // quadrature forcer command, fraction of full scale [-1, 1]
  double pump_v = 0;       // pump amplitude at the electrode, written for the next block
  double row_pump_v = 0;   // pump amplitude the row's quadratures saw (its demodulator window)
  double pump_phase_rad = 0;
  double agc_setpoint_v = 0;  // wave amplitude set point at the pickoff
  Mode mode = Mode::power_up;
  bool exc_on = false;        // firmware's excitation command
  bool exc_line = false;      // excitation enable line as driven
  bool fault_input = false;   // board fault input
  bool ident_active = false;  // identification (window schedule) running
  bool comp_valid = false;    // the drift compensation is in force and its model checks agree
  uint8_t comp_reasons = 0;   // why not: fw::CompensationReason bits (0 when valid)
  // The model's damping anisotropy against the pickoff self-identification's
  // (standard errors; fw::EstimatorHealth::readout_damping_sigmas).
  double readout_damping_sigmas = 0;
  // Do no harm for a calibration: its correction of the pickoffs was
  // withdrawn, its damping model or its gap harmonic refuted (each taken out).
  bool cal_withdrawn = false;
  bool cal_damping_refuted = false;
  bool cal_gap_refuted = false;
  uint16_t faults = 0;  // Fault bits
  double temp_c = 0;
  // Identification: p = (nu, dnu_C, dnu_S, dw_C, dw_S) of physics.md section 5.
  double nu_per_s = 0, dnu_c_per_s = 0, dnu_s_per_s = 0;
  double dw_c_rad_s = 0, dw_s_rad_s = 0;
  double cond_log10 = 0;  // log10 of the condition number of H^T H
  double coverage = 0;    // coverage of the 4 theta circle by the windows, [0, 1]
  uint32_t windows = 0;   // free-decay windows accumulated
  bool est_valid = false;
  // Executive statistics.
  uint32_t overruns = 0;
  uint32_t missed_ticks = 0;
  uint32_t max_frame_us = 0;
  double cpu_load_pct = 0;
  // Configuration echoed for readers (recordings need K).
  double angular_gain = 0;
  double window_period_s = 0;
  double window_length_s = 0;
  // CAN driver state.
  hal::CanCounters can{};
  hal::CanState can_state = hal::CanState::error_active;
  // The firmware's own readings for a calibration (HRG_CAL_READINGS): read
  // at a set's first page and held for the others; the firmware refreshes
  // them only then (TelemetryEncoder::cal_readings_due).
  FirmwareEstimates estimates{};
};

// Telemetry rates per message (index = Tm), in Hz; 0 switches a message off.
// Every non-zero rate must divide the base rate so a message is sent on whole
// base frames.
struct TelemetryConfig {
  std::array<uint16_t, kTelemetryCount> rate_hz{};
  static TelemetryConfig defaults();
  // True when every rate is 0 or divides base_rate_hz, and the two wave
  // messages and HRG_ROW (the parts of one recording row) have the same rate.
  bool valid(uint32_t base_rate_hz) const;
};

// Bus load (fraction of the bit rate) of a configuration, worst-case stuffing.
double bus_load_fraction(const TelemetryConfig& config, uint32_t bitrate_bps);

// Encodes one telemetry message from the snapshot with the given sequence
// value (HRG_CAL_READINGS: its page 0).
void encode_telemetry(Tm message, const TelemetrySnapshot& s, uint8_t seq, hal::CanFrame& out);

// One page of HRG_CAL_READINGS (page < kCalReadingsPages). Values outside a
// signal's range saturate (a sigma above its range reads as that range's
// end); no feedthrough reading is sent as 0 edges and zeros.
void encode_cal_readings(const FirmwareEstimates& e, uint8_t page, uint8_t seq, hal::CanFrame& out);

// The test bench's LAB_TABLE frame (input rate, temperature): written by the
// simulator's runner for its rate table, and by tests.
hal::CanFrame encode_lab_table(double rate_dps, double temp_c, uint8_t seq);

// Emits the telemetry due in each base frame, with per-message sequence counters.
// Calling context: the executive's telemetry task, once per base frame. No heap.
class TelemetryEncoder {
 public:
  // An invalid config (see TelemetryConfig::valid) is replaced by the defaults;
  // `config_ok()` tells which happened.
  TelemetryEncoder(const TelemetryConfig& config, uint32_t base_rate_hz);

  // Writes the frames due in this base frame into `out` (at most
  // kTelemetryCount) and returns how many. Messages are staggered (message i is
  // sent when (frame + i) is a multiple of its period) to spread the load;
  // HRG_WAVE_Y and HRG_ROW always go with HRG_WAVE_X, and none of the three
  // while the snapshot's row is not ready.
  std::size_t tick(const TelemetrySnapshot& s, std::span<hal::CanFrame> out);
  // Encodes one message now (e.g. STATUS on request), advancing its counter
  // (and HRG_CAL_READINGS' page).
  void encode_now(Tm message, const TelemetrySnapshot& s, hal::CanFrame& out);
  // True when the next tick() sends page 0 of HRG_CAL_READINGS: the
  // snapshot's `estimates` are read then and held for the set's pages (the
  // firmware computes them for that tick only).
  bool cal_readings_due() const;
  bool config_ok() const { return config_ok_; }
  const TelemetryConfig& config() const { return config_; }

 private:
  TelemetryConfig config_;
  uint32_t base_rate_hz_;
  bool config_ok_;
  uint64_t frame_ = 0;
  std::array<uint8_t, kTelemetryCount> seq_{};
  uint8_t page_ = 0;          // HRG_CAL_READINGS' next page
  FirmwareEstimates held_{};  // ... and the readings its set is sent from
  // Whether message i is sent in the frame `frame` (its period and stagger).
  bool due(std::size_t i, uint64_t frame) const;
};

}  // namespace hrg::fw::can
