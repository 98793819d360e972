// SPDX-License-Identifier: MIT
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "characterize/allan.hpp"
#include "characterize/drift_series.hpp"
#include "characterize/noise_terms.hpp"
#include "characterize/scale_factor.hpp"
#include "sim_run/run.hpp"

namespace hrg::characterize {

// The test procedures of IEEE Std 1431 / 952 run on the firmware and the
// simulated target through the main job's runner (sim_run::run_simulation): each
// procedure builds a rate-table (and temperature) schedule after the ring-up
// and the identification sweep, runs it and reads its figures from the
// telemetry rows, the way a test engineer reads them from a test record.
struct ProcedureOptions {
  std::string scenario;    // TOML scenario (empty: the default gyro of `hrg sim`)
  bool short_run = false;  // shortened records (the CTest): the same steps, less time each
  int turn_ons = 3;        // bias repeatability: turn-ons with different noise seeds
  // Independent runs (the turn-ons) this many at a time, 0: every core. The
  // results are the same for every value.
  unsigned jobs = 0;
  bool progress = false;
};

// The procedure's job before its schedule: the scenario's (or the default)
// target and firmware, ring-up and the identification sweep in `schedule`.
struct ProcedureBase {
  sim_run::RunConfig job;
  double earth_rad_s = 0.0;  // constant input besides the table (Earth rate)
};
ProcedureBase procedure_base(const ProcedureOptions& o);

// --- scale factor series (IEEE 1431 12.9) ---
struct ScaleFactorResult {
  std::vector<RateStep> steps;  // compensated output over whole 4 theta cycles of the pattern
  ScaleFactorSeries series;
  std::vector<double> true_theta_rad, read_theta_rad;  // the slowest steps' turns
  AngleDependentScaleFactor readout;
  double wall_s = 0.0, sim_s = 0.0;
};
ScaleFactorResult run_scale_factor(const ProcedureOptions& o);

// --- drift rate series (IEEE 1431 12.11) ---
struct DriftResult {
  // Angle-dependent bias of the main job's parked-angle test.
  sim_run::BiasFit adb_raw, adb_comp, adb_model;
  std::vector<sim_run::ParkResult> parks;
  double theta_at_sweep_end_deg = 0.0;  // the firmware's pattern angle after the sweep
  double pattern_per_case = 0.0;        // pattern angle per case angle (-K / 2), measured
  std::vector<double> turn_on_bias_dph;
  Repeatability repeatability;
  std::vector<double> temperature_c, temperature_bias_dph;  // compensated output, per segment
  std::vector<double> temperature_raw_bias_dph;             // raw output, same segments
  double temperature_model_dph = 0.0;  // mean true D / K (at T0) over the ramp's holds
  TemperatureSlope temperature, temperature_raw;
  double wall_s = 0.0, sim_s = 0.0;
};
// The parked-angle test alone (the limits procedure needs its 4 theta fit).
DriftResult run_angle_dependent_bias(const ProcedureOptions& o);
DriftResult run_drift(const ProcedureOptions& o);
// The bias over o.turn_ons turn-ons alone (turn_on_bias_dph, repeatability).
DriftResult run_bias_repeatability(const ProcedureOptions& o);

// --- input rate limits and rate threshold (IEEE 1431 12.10), run-down (12.14) ---
struct ThresholdStep {
  double input_dph = 0.0;  // table + Earth
  double raw_dph = 0.0;    // raw output rate at the least favourable angle
  double comp_dph = 0.0;   // compensated output rate
};
struct LimitsResult {
  double closed_form_dph = 0.0;     // nu dmu / K of the resonator
  double predicted_raw_dph = 0.0;   // true D / K at the angle of the holds
  double predicted_comp_dph = 0.0;  // (true D - the firmware's D) / K there
  double measured_raw_dph = 0.0;    // where the raw output rate crosses zero
  double measured_comp_dph = 0.0;
  double theta_hold_deg = 0.0;  // pattern angle of the holds (least favourable)
  std::vector<ThresholdStep> threshold_steps;
  std::vector<RateStep> rate_limit_steps;  // ascending; the last may have failed
  std::vector<bool> followed;
  double largest_followed_dps = 0.0;
  bool limit_reached = false;  // a tested rate was not followed
  double wall_s = 0.0, sim_s = 0.0;
};
// The rate threshold at the least favourable angle of the parked-angle
// test's 4 theta fit, then ascending rate steps until one is not followed.
LimitsResult run_limits(const ProcedureOptions& o, const DriftResult& adb);

// --- angle storage and run-down (IEEE 1431 12.13, 12.14) ---
// The excitation switched off (safe mode through the board's fault input)
// after the ring-up and the sweep; the chain reads the free decay.
struct RundownResult {
  double decay_rate_per_s = 0.0;            // measured: slope of ln(amplitude)
  double decay_rate_predicted_per_s = 0.0;  // the free-decay closed form over the same record
  double amplitude0_v = 0.0, noise_floor_v = 0.0;
  double rundown_s = 0.0;              // ln(a0 / floor) over the measured decay rate
  double rundown_predicted_s = 0.0;    // closed form of the resonator (two damping axes)
  double readout_error_max_deg = 0.0;  // read pattern angle - true, over the record
  std::vector<double> t_s, amplitude_v, model_v;
  double wall_s = 0.0, sim_s = 0.0;
};
RundownResult run_rundown(const ProcedureOptions& o);

// --- noise (IEEE 952) on a still record ---
struct NoiseResult {
  std::vector<AllanPoint> curve;  // rad/s
  NoiseTerms terms;
  double record_s = 0.0;
  // The pickoff noise read as angle: a demodulated amplitude noise sigma_a
  // per block tilts the pattern by sigma_a / (2 a), the output by 2 / K of
  // that; a white angle noise sigma_x gives adev = sqrt(3) sigma_x / tau. The
  // block's decimating filter only lowers it: an upper bound (rad).
  double readout_angle_noise_bound_rad = 0.0;
  double wall_s = 0.0, sim_s = 0.0;
};
NoiseResult run_noise(const ProcedureOptions& o);

// The names `--test` takes, in the order `all` runs them.
std::span<const std::string_view> procedure_names();

// Runs the named procedures (`all`: every one) and writes their data sheet
// sections. Throws std::invalid_argument naming an unknown procedure.
struct ProcedureReport {
  std::string sheet_json;
  std::vector<std::string> lines;  // one line of figures per procedure, with its times
  double wall_s = 0.0, sim_s = 0.0;
};
ProcedureReport run_procedures(std::span<const std::string> names, const ProcedureOptions& o);

}  // namespace hrg::characterize
