// SPDX-License-Identifier: MIT
#pragma once

#include "dsp/chain.hpp"
#include "estimator/estimator.hpp"
#include "firmware/calibration.hpp"
#include "firmware/dsp_chain_port.hpp"
#include "firmware/gyro.hpp"

namespace hrg::fw::app {

// The firmware's whole configuration: the executive's (windows, bands,
// monitors), the signal chain's and the estimator's. K (`gyro.angular_gain`)
// and the AGC set point (`gyro.amplitude_set_v`) are set in `gyro` only;
// derive() copies them, and the converter layout, to the parts that need
// them. Change them there and call derive() again.
struct FirmwareConfig {
  GyroConfig gyro;
  dsp::ChainConfig chain;
  est::Estimator::Config estimator;
  // What the firmware corrects of this gyro's electronics (the identity by
  // default; a file, a CAN block or the built-in constant on bare metal).
  Calibration calibration = kIdentityCalibration;
  // The uncertainty of `calibration`'s gap harmonic (a file's sigmas; zero:
  // not given). A gap put in force later that differs from it (a CAN
  // block's) comes without one.
  GapSigma calibration_gap_sigma{};
  // The pickoff self-calibration's estimate (gain, misalignment) folded into
  // the correction in force when it is well conditioned and significant
  // (Firmware::self_calibrate); the identification then starts again.
  bool online_pickoff_calibration = false;
};

// How the free-decay windows identify the resonator.
enum class WindowPlan : uint8_t {
  // 1 s windows every 2 s, 4 per 4 theta bin (2 at least): the main job's
  // few-minute runs.
  standard,
  // 5 s windows every 10 s, 4 per bin, all required: runs of an hour or more
  // with an identification phase of their own; then a check window at least
  // every 10 min and continued identification at 2 % excitation off.
  long_run,
};

// Settling delay of both plans before the first check window of a model
// newly in force (WindowConfig::first_check_delay_frames; base frames at
// 1 kHz): 20 s, the standard plan's check period, so that plan's schedule is
// unchanged; in the long-run plan two window periods (the period lets the
// amplitude return to its set point after a window) instead of the 10 min
// between later checks.
inline constexpr uint32_t kFirstCheckDelayFrames = 20 * kBaseRateHz;

// Excitation-off share that continued identification keeps to in operation
// (WindowConfig::operation_duty).
inline constexpr double kDefaultOperationDuty = 0.02;

// The firmware's defaults for a board with this converter layout, derived.
FirmwareConfig default_firmware_config(const ConverterLayout& conv,
                                       WindowPlan plan = WindowPlan::standard);

// Sets the window plan's fields of `w` (the others are left alone).
void apply_window_plan(WindowConfig& w, WindowPlan plan);

// Share of the amplitude decay time (Q / (pi f)) an operation window may
// last (WindowConfig::operation_length_frames).
inline constexpr double kOperationWindowDecayShare = 0.1;

// Shortens the operation windows to kOperationWindowDecayShare of the
// resonator's decay time (from the chain's Q and centre frequency), never
// below the campaign's windows; a length of 0 (the campaign's) is kept.
void limit_operation_windows(WindowConfig& w, const dsp::ChainConfig& chain);

// Fills the derived fields: the chain's converter fields from `conv`, the
// operation windows' limit from the chain's Q, and K and the set point from
// `cfg.gyro` into the chain, the estimator and the monitor, and the
// telemetry's envelope reference from the chain.
void derive(FirmwareConfig& cfg, const ConverterLayout& conv);

// The telemetry's fixed reference (the chain's centre frequency), the
// envelope's centre and the blocks until a row is free of the drive.
can::EnvelopeReferenceConfig envelope_reference_config(const dsp::ChainConfig& chain,
                                                       const ConverterLayout& conv);

// Blocks after the drives go off until a demodulated row is free of them: the
// last driven DAC word (played dac_lead_frames + `dac_latency_samples` after
// its block) lies before the N (L - 1) + 1 samples the demodulator averages.
uint32_t drive_free_blocks(const dsp::ChainConfig& chain, double dac_latency_samples);

// The instant the pump stops, in rows after the last block the chain ran
// with it on: that block's last DAC word (held dac_lead_frames - 1/2 .. + 1/2
// after its frame) ends dac_lead_frames + L - 1/2 frames after the block's
// start; a row is centred N (L - 1)/2 frames before its last sample. 3.505 at
// the default 100-frame blocks (PumpEdgeCheckConfig::edge_offset_rows).
double pump_edge_offset_rows(const dsp::ChainConfig& chain);
// Rows between the record that writes a pump (ChainOutputs::pump_v, for the
// next block) and the row whose centre it acts at: the pump written at row n
// acts from row n + pump_edge_offset_rows - 1 to n + pump_edge_offset_rows,
// so at the centre of that interval rounded to a row (3 at the default
// chain). The pump's gap fit integrates the pump that lag back
// (est::PumpDriftEstimator::Config::pump_lag_samples).
int pump_lag_samples(const dsp::ChainConfig& chain);

}  // namespace hrg::fw::app
