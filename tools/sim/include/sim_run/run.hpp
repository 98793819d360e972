// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "firmware/app/calibration_guard.hpp"
#include "estimator/pickoff_self_calibration.hpp"
#include "firmware/app/firmware.hpp"
#include "firmware/app/firmware_config.hpp"
#include "sim_target/control.hpp"
#include "sim_target/sim_config.hpp"
#include "sim_run/analysis.hpp"

namespace hrg::fw::app {
class Firmware;
}
namespace hrg::sim {
class SimTarget;
}

namespace hrg::sim_run {

// One parked interval of the angle-dependent-bias test: the case is still,
// the pattern sits at one angle, and the bias is the slope of the angle error.
struct ParkedInterval {
  double t_begin_s = 0.0;  // measurement starts (after the settle time)
  double t_end_s = 0.0;
};

// A fault injected through the simulated target's back door at time t_s.
struct FaultEvent {
  enum class Kind : uint8_t { adc_stuck, adc_saturated, dac_dead, fault_input, can_bus_off };
  double t_s = 0.0;
  Kind kind = Kind::adc_stuck;
  std::size_t channel = 0;  // ADC 0 = x, 1 = y; DAC 0 = pump, 1 = fx, 2 = fy
  bool on = true;
};

// Everything the main job needs: the simulated target, the firmware and its
// parts, the input schedule and what to record.
struct RunConfig {
  sim::SimConfig sim;
  fw::app::FirmwareConfig firmware;  // derived from `sim` by derive_firmware_config
  double duration_s = 0.0;
  double latitude_deg = 55.75;
  double earth_rate_rad_s = 0.0;      // vertical component of the Earth rate in the input
  double telemetry_hz = 100.0;        // rows of telemetry.csv per simulated second
  double sweep_end_s = 0.0;           // end of the turning (identification) phase
  std::vector<ParkedInterval> parks;  // the bias test (empty: none)
  std::vector<FaultEvent> faults;     // in time order
  std::string description;
  // The drift requirement the compensated angle-dependent bias is to meet
  // (the seed paper's 3 deg/h): the run length a resonator needs is taken
  // from when its model's bias uncertainty reaches a third of it.
  double bias_goal_dph = 3.0;
};

// The default scenario: the seed's resonator (5 kHz, Q 5e6, dQ/Q 0.1, split
// 5e-4 Hz), a 24-bit 100 kHz ADC with white noise, Earth rate at 55.75 deg N,
// ring-up from rest, a rate-table sweep that turns the pattern twice through
// the 4 theta circle, then the pattern parked at `bias_angles` angles on a
// still base. `duration_s` <= 0 takes the default length; a longer duration
// lengthens the parks; a shorter one drops the parks that do not fit.
RunConfig default_run(double duration_s, int bias_angles = 16);

// The static-base variant: the same resonator on a still table (Earth rate
// only). The firmware fills the 4 theta bins by turning the pattern on
// purpose (pattern-angle command through the forcers) between windows; the
// output is held while the pattern is moved. Default length 300 s.
RunConfig static_base_run(double duration_s);

// The simulated board's converter layout, as the firmware's chain must know it.
fw::ConverterLayout converter_layout(const sim::SimConfig& sim);

// Fills the firmware's derived fields (chain converters, K and the set point
// where they are copied) from the simulated board and `job.firmware.gyro`, so
// that a scenario only has to describe the target.
void derive_firmware_config(RunConfig& job);

// One telemetry row (the recording's columns plus the truth).
struct TelemetryRow {
  double t_s, cx_v, sx_v, cy_v, sy_v;
  int exc;             // 1 unless the row's whole averaging span was free of drive
  int excitation_cmd;  // the firmware's excitation command for this block
  double pump_v, temp_c, rate_dps;
  double pll_hz;  // the PLL (NCO) frequency; cx..sy are against the fixed f_ref_hz
  double quad_v;
  int mode;
  double theta_deg, out_angle_deg, raw_angle_deg, true_angle_deg, true_theta_deg;
  double a_A_v, a_B_v, drift_model_dph, drift_true_dph;
  double drift_control_dph;   // the control-loop part of drift_model_dph
  double drift_withheld_dph;  // the D_Phi/K the firmware did not apply (readout pattern)
  int out_valid;
  int pattern_cmd;                // the pattern is being moved on purpose
  int comp_valid;                 // the drift compensation is in force (its model checks agree)
  int comp_reasons;               // why not: fw::CompensationReason bits (0 when valid)
  double readout_damping_sigmas;  // the model check against the readout's pattern
  // Output minus truth, accumulated only between consecutive rows with a
  // valid output (a held output while the pattern is moved on purpose does
  // not count as an error), deg.
  double raw_error_deg, out_error_deg;
};

// The model's uncertainty after an accepted solve: the damping anisotropy's
// standard errors as input rate (hypot of the cos and sin terms), deg/h.
struct ConvergencePoint {
  double t_s = 0.0;
  double bias_sigma_dph = 0.0;
};

// When the model's bias uncertainty reaches target_dph: the first point at
// or below it (measured), else the time its information 1/sigma^2 reaches
// 1/target^2 at the rate it grew over the last half of the points
// (extrapolated); t_s -1 when there is no estimate (fewer than 4 points, no
// growth).
struct GoalTime {
  double t_s = -1.0;
  bool extrapolated = false;
};
GoalTime uncertainty_goal_time(std::span<const ConvergencePoint> c, double target_dph);

struct ParkResult {
  double theta_rad = 0.0;       // mean pattern angle while parked
  double bias_raw_dph = 0.0;    // slope of (raw output - true angle), input-rate units
  double bias_comp_dph = 0.0;   // same with the drift compensation
  double bias_model_dph = 0.0;  // the true D/K at that angle (what the model predicts)
  // The firmware reported its compensation valid over the whole park; the
  // compensated fit takes only such parks.
  bool model_valid = false;
};

struct TaskFigures {
  std::string name;
  uint32_t rate_hz = 0;
  uint32_t budget_ns = 0;
  uint32_t min_ns = 0;
  uint32_t max_ns = 0;
  double mean_ns = 0.0;
  uint32_t overruns = 0;
  uint32_t slips = 0;
  uint64_t runs = 0;
};

// The firmware's own estimates of what a calibration holds, beside the
// audit's (fw::app::Firmware::estimates(); HRG_CAL_READINGS on the bus).
using FirmwareEstimates = fw::can::FirmwareEstimates;

struct RunResult {
  bool reached_operate = false;
  double t_operate_s = -1.0;  // first time in operate
  fw::Mode final_mode = fw::Mode::power_up;
  uint16_t faults_seen = 0;
  double sim_s = 0.0;
  double wall_s = 0.0;
  double cpu_s = 0.0;                // the thread's CPU time in the loop
  double realtime_factor = 0.0;      // simulated s per wall s
  double realtime_factor_cpu = 0.0;  // simulated s per CPU s (what one free core gives)
  double sim_share = 0.0;            // share of the wall time spent in the simulated ADC (physics)
  // The same share by CPU time: over the stretches of the run that the
  // thread's CPU clock shows ran unpreempted (lockstep; negative if none).
  double sim_share_cpu = -1.0;
  double share_stretches_kept = 0.0;  // fraction of the stretches that did
  double adc_wait_mean_us = 0.0;      // mean time per frame inside Adc::read_block (the simulation)
  sim::SimStageTimes sim_stages;      // host time per stage of read_block (RunOptions::profile)
  double excitation_off_fraction = 0.0;
  uint32_t windows = 0;
  uint32_t windows_accepted = 0;
  bool campaign_done = false;
  fw::Identification identification{};
  std::array<double, 5> truth{};
  double condition = 0.0;
  double coverage = 0.0;
  // Cramer-Rao bound (standard deviation) of each parameter for the windows
  // taken, at the per-sample amplitude noise noise_sigma_v (from the ADC
  // noise through the demodulator).
  std::array<double, 5> crb_sigma{};
  double noise_sigma_v = 0.0;
  double t_converged_s = -1.0;          // the window campaign ended (model applied)
  double control_drift_mean_dph = 0.0;  // mean D_Phi/K added over the valid output
  // ... and withheld (the readout's pattern explained what D_Phi's fits read).
  double control_drift_withheld_mean_dph = 0.0;
  // Do no harm: the compensation in force at the end (its model checks
  // agreed), the failed checks, the last check window's misfit.
  bool compensation_valid = false;
  bool compensation_applied = false;
  uint32_t model_checks_failed = 0;
  double last_window_misfit = 0.0;
  // Why not valid at the end (fw::CompensationReason bits), the model check
  // against the readout's pattern, the readout pattern's own significance,
  // the readout phase's significance and drift share, and the pump's D_Phi
  // fit (its gap harmonic, how many sigmas, usable).
  uint8_t compensation_reasons = 0;
  double readout_damping_sigmas = 0.0;
  double readout_pattern_sigmas = 0.0;
  double readout_phase_sigmas = 0.0;
  double readout_phase_drift_share = 0.0;
  double pump_gap = 0.0;
  double pump_gap_sigmas = 0.0;
  // The fit's gap harmonic (eps_p, eps_q) and their one-sigma uncertainties
  // (the covariance pump_gap_sigmas weighs with); 0 before the fit is valid.
  std::array<double, 4> pump_eps_pq_sigma{};
  bool pump_drift_usable = false;
  // The calibration's trial (source, verdict, the misfits that judged it).
  fw::app::CalibrationStatus calibration{};
  // The firmware's pickoff self-calibration at the end (its last solve).
  est::PickoffSelfCalResult self_calibration{};
  fw::app::SelfCalibrationStatus self_calibration_applied{};
  // The pickoff map the firmware keeps for the next power-up
  // (fw::app::Firmware::pickoff_map_to_keep).
  est::PickoffMap self_calibration_keep{};
  fw::Calibration final_calibration{};
  fw::PumpEdgeStatus pump_edge{};  // the switch-off step check at the end
  // What the firmware itself read of a calibration's values, for the next
  // hrg audit --calibration (the recording's header, report.json).
  FirmwareEstimates firmware_estimates{};
  std::vector<TelemetryRow> rows;
  std::vector<ParkResult> parks;
  BiasFit fit_raw, fit_comp, fit_model;
  // The bias test against the firmware's own word: parks with the model
  // valid throughout (fit_comp is over these only), when it first became
  // valid, and the run length the resonator needs for every park to be
  // measured with it (0 when this run was long enough).
  std::size_t parks_model_valid = 0;
  double t_model_valid_s = -1.0;
  double bias_test_needs_s = 0.0;
  // The model's bias uncertainty after each accepted solve, and when it
  // reaches a third of RunConfig::bias_goal_dph: measured (the run got there)
  // or extrapolated from the information's recent growth (-1: no estimate).
  std::vector<ConvergencePoint> convergence;
  double bias_goal_dph = 0.0;  // RunConfig::bias_goal_dph
  double t_bias_goal_s = -1.0;
  bool t_bias_goal_extrapolated = false;
  std::vector<AllanPoint> allan;  // of the compensated output rate, rad/s
  double allan_span_s = 0.0;      // length of the still stretch it was computed on
  double tracking_rms_deg = 0.0;  // compensated output - true, after operate
  double tracking_max_deg = 0.0;
  double raw_error_end_deg = 0.0;    // raw output - true at the end
  double comp_error_end_deg = 0.0;   // compensated output - true at the end
  double model_error_end_deg = 0.0;  // -integral of the true D/K over the valid output
  double drift_bound_deg = 0.0;      // integral of |true D|/K: the drift model's bound
  std::vector<TaskFigures> tasks;
  fw::FrameStats frames{};
  uint64_t can_frames = 0;
  uint32_t can_bus_off_events = 0;  // the simulated controller's count
  uint32_t can_restarts = 0;        // restarts the firmware made after bus-off
  double t_can_back_s = -1.0;       // first frame on the bus after the last bus-off
  uint32_t mode_changes = 0;
  double t_first_fault_s = -1.0;   // first frame in fault or safe
  double t_back_operate_s = -1.0;  // first return to operate after that
  bool real_time = false;
  std::string realtime_setup;         // what SCHED_FIFO / mlockall gave (real time only)
  std::vector<std::string> failures;  // empty: the run passed
};

struct RunOptions {
  bool progress = false;   // a bar on stderr
  std::string can_log;     // when not empty: every CAN frame as a candump log
  bool real_time = false;  // pace frames by CLOCK_MONOTONIC (1 ms) instead of lockstep
  int rt_priority = 80;    // SCHED_FIFO priority asked for in real time
  bool profile = false;    // time the simulated target's stages (RunResult::sim_stages)
  // Called every observe_every_s of simulated time with the firmware and the
  // simulated target (benches and studies that follow the identification).
  std::function<void(const fw::app::Firmware&, const sim::SimTarget&)> observer;
  double observe_every_s = 60.0;
};

// Runs firmware + simulated target: in lockstep (as fast as the host allows,
// deterministic) or paced in real time with the same executive code, where
// deadline misses are counted and the real-time setup is reported.
RunResult run_simulation(const RunConfig& job, const RunOptions& options);

// Fills the figures of `r` from its rows (errors against the truth, the
// parked-angle bias and its fits, the Allan deviation on a still table).
void analyse_run(RunResult& r, const RunConfig& job);

// The true drift D (rad/s, Omega K units) of the resonator at pattern angle
// theta with quadrature ratio a_B/a_A (physics.md section 3, D_nu + D_w).
double true_drift_rad_s(const sim::ResonatorParams& p, double theta_rad, double ab_over_aa);

// p = (nu, dnu_C, dnu_S, dw_C, dw_S) of the simulated resonator.
std::array<double, 5> true_parameters(const sim::ResonatorParams& p);

}  // namespace hrg::sim_run
