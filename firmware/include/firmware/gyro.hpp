// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>

#include "firmware/angle_output.hpp"
#include "firmware/can/command.hpp"
#include "firmware/can/envelope_reference.hpp"
#include "firmware/can/link.hpp"
#include "firmware/can/telemetry.hpp"
#include "firmware/compensation_reason.hpp"
#include "firmware/executive.hpp"
#include "firmware/fault_monitor.hpp"
#include "firmware/mode.hpp"
#include "firmware/mode_machine.hpp"
#include "firmware/pump_edge_check.hpp"
#include "firmware/chain_and_identifier.hpp"
#include "firmware/window_scheduler.hpp"
#include "hal/board.hpp"

namespace hrg::fw {

struct GyroConfig {
  double angular_gain = 0.554;           // K, from calibration (2 x Bryan factor)
  double amplitude_set_v = 1.0;          // AGC set point for a_A at the pickoff
  double amplitude_band = 0.05;          // |a_A - set| / set inside this counts as settled
  double quadrature_band = 0.02;         // |a_B / a_A| inside this counts as settled
  uint32_t self_test_frames = 20;        // power_up: clean frames before ring-up
  uint32_t settle_frames = 200;          // lock: frames inside the bands before operate
  uint32_t reacquire_frames = 10;        // recover: frames inside the bands before operate
  uint32_t fault_hold_frames = 500;      // fault: clean frames before a retry
  bool compensate_drift = true;          // add the drift model (after the window campaign)
  bool compensate_control_drift = true;  // and D_Phi with the excitation on (needs the model)
  bool identify = true;                  // run the windows (off: use the model it has)
  // Windows after the campaign (checks, WindowConfig::operation_duty) are
  // folded into the identification after their check, so the model keeps
  // converging and follows slow changes (off: they only check it).
  bool continue_identification = true;
  // Do no harm: the model applied at the end of the campaign is withdrawn
  // for good as soon as a check window disagrees with it (misfit,
  // EstimatorHealth::window_misfit, above this): the output is then the raw
  // angle, reported so.
  double max_window_misfit = 4.0;
  // ... or far below it: a still free decay much quieter than the fit's own
  // residual (sigma_hat) says the campaign's windows carried a signal the
  // model does not have (a pickoff misalignment's 4 theta pattern in E while
  // the table turns), which inflated sigma_hat and with it the tolerance of
  // every check. When the model holds, the misfit is 1 +- ~0.1.
  double min_window_misfit = 0.25;
  // ... and not while the model's damping anisotropy stands more than this
  // many standard errors from the one solved with the pickoff level patterns
  // alongside (EstimatorHealth::readout_damping_sigmas): the model then took
  // a pickoff gain or misalignment's 4 theta pattern in E, read while the
  // table turned, for damping. The significance the firmware asks of the
  // same identification before it applies it (fw::app::
  // SelfCalibrationRounds::kSignificance). 0: not checked.
  double max_readout_damping_sigmas = 5.0;
  // D_Phi is not applied while the readout's own 4 theta pattern explains
  // what its fits read: the check above trips, or the pickoff
  // self-identification's gain or misalignment stands more than this many
  // standard errors from zero (EstimatorHealth::readout_pattern_sigmas). A
  // gain g reads the amplitude as a (1 + g sin^2 2theta): its level pattern,
  // seen while the table turns, is a 4 theta rate in ln a that the pump's
  // fit takes for a gap harmonic (0.18-0.36 at g 0.01 on the 4.2 kHz
  // resonator of tools/gregory/README.md). 0: not checked.
  double max_readout_pattern_sigmas = 5.0;
  // ... and not while the pickoff self-identification reads a phase lag
  // more than this many standard errors from zero (EstimatorHealth::
  // readout_phase_sigmas; the correction in force, if any, already taken
  // out) whose drift 2 nu |phi| is more than max_readout_phase_drift_share of
  // the drift the model removes (EstimatorHealth::readout_phase_drift_share):
  // the model has no such drift, the raw output holds both, so beyond 1/2
  // the compensated output may be worse than raw. 0: not checked.
  double max_readout_phase_sigmas = 5.0;
  double max_readout_phase_drift_share = 0.5;
  // Do no harm while the pump runs: the step of the corrected signal at
  // every switch-off (PumpEdgeCheck). A step above its tolerance makes the
  // compensation not valid.
  PumpEdgeCheckConfig pump_edge{};
  WindowConfig windows{};
  MonitorConfig monitor{};
  // How the telemetry's envelopes are referred and stamped (set from the
  // chain and the converters by the firmware's configuration).
  can::EnvelopeReferenceConfig envelope{};
  // The guarded calibration write over CAN (the secret is this gyro's).
  can::CalTransferConfig calibration_service{};
};

// Everything the firmware reports once per frame (telemetry, recordings).
struct GyroStatus {
  ChainRecord chain{};
  Mode mode = Mode::power_up;
  uint16_t faults = 0;
  bool excitation_on = false;  // drives permitted by the mode (exc column)
  bool enable_line = false;
  bool fault_input = false;
  bool pattern_control = false;
  double theta_unwrapped_rad = 0.0;
  double out_angle_rad = 0.0;
  double out_raw_angle_rad = 0.0;
  double out_rate_rad_s = 0.0;
  double drift_rad_s = 0.0;          // D used for the correction (Omega K units)
  double control_drift_rad_s = 0.0;  // its control-loop part D_Phi
  // The D_Phi the estimator gave and the firmware did not apply
  // (CompensationReason::control_drift_withheld), rad/s; 0 otherwise.
  double control_drift_withheld_rad_s = 0.0;
  bool out_valid = false;
  // The drift compensation is in force: the campaign has ended and no check
  // window has disagreed with its model (false for good after one did).
  bool compensation_applied = false;
  // ... and a check window has agreed with it, and the switch-offs show no
  // step of the corrected signal (pump_edge): the compensated output is one
  // the firmware stands behind.
  bool compensation_valid = false;
  // Why not (CompensationReason bits; 0 when valid), and the model check
  // against the readout's pattern behind one of them
  // (EstimatorHealth::readout_damping_sigmas), both from check_model().
  uint8_t compensation_reasons = reason_bit(CompensationReason::not_in_force);
  double readout_damping_sigmas = 0.0;
  PumpEdgeStatus pump_edge{};
  uint32_t model_checks_failed = 0;
  uint32_t adc_errors = 0;
  uint32_t adc_missed_blocks = 0;
  uint32_t dac_errors = 0;
  uint64_t adc_wait_ns = 0;  // timer time spent in Adc::read_block (lockstep: the simulation)
  // The resonator's temperature as the board's sensor last read it (degC);
  // temp_valid false while the board has none or its read fails.
  double temp_c = 0.0;
  bool temp_valid = false;
  uint32_t temp_errors = 0;  // reads that failed (io_error etc.; `closed` is no sensor)
};

// The firmware: wires the HAL board, the signal chain and the identifier to
// the executive, the mode machine, the monitors, the interval shutdown
// scheduler and the angle output. Everything is allocated at construction.
class Gyro {
 public:
  static constexpr std::size_t kTaskCount = 8;
  // CAN command frames handled per command task run (the rest wait).
  static constexpr uint32_t kCommandsPerRun = 4;
  // Command task runs spent bus-off before the link restarts the CAN
  // controller (0.1 s at 100 Hz: more than the 128 x 11 recessive bits the
  // controller needs, and a faulty bus is not hammered).
  static constexpr uint32_t kCanRestartRuns = 10;
  // Frames the output stays held after a commanded pattern move (longer than
  // the DAC and demodulator latency, a few frames).
  static constexpr uint32_t kPatternHoldFrames = 20;

  // `timer` measures task execution time (the board clock in real time, a
  // host clock in lockstep).
  Gyro(hal::Board& board, SignalChain& chain, ResonatorIdentifier& identifier,
       hal::MonotonicClock& timer, Pacing pacing, const GyroConfig& cfg);

  // Runs one base frame (paced by the board's ADC block and clock).
  void run_frame() { exec_.run_frame(*this); }

  // Commands (CAN or host), applied at the next frame.
  void command_pattern_angle(double theta_rad);
  void release_pattern();
  void command_safe() { mode_.handle(Event::command_safe); }
  void command_restart() { mode_.handle(Event::command_restart); }
  // A new window campaign from scratch, the model checks with it (the
  // signals the identifier saw changed: a new pickoff correction). The
  // identifier is restarted by its owner. Call outside a window.
  void restart_identification();
  // The model in force changed without a new campaign (a calibration put in
  // force, a part of it taken out): its first check window comes after the
  // settling delay (WindowConfig::first_check_delay_frames), not a whole
  // check period later.
  void model_changed() { scheduler_.model_changed(); }
  // The correction of the pickoffs changed: the switch-off steps seen
  // through the old one are forgotten.
  void restart_pump_edge_check() {
    pump_edge_.reset();
    status_.pump_edge = pump_edge_.status();
  }
  // Re-zeroes the output angle at the current pattern angle.
  void zero_output() { output_.rereference(); }

  const GyroStatus& status() const { return status_; }
  const Executive<Gyro, kTaskCount>& executive() const { return exec_; }
  const ModeMachine& mode_machine() const { return mode_; }
  const WindowScheduler& scheduler() const { return scheduler_; }
  const AngleOutput& output() const { return output_; }
  const ResonatorIdentifier& identifier() const { return identifier_; }
  const GyroConfig& config() const { return cfg_; }
  // False when the board's converters do not match the firmware's block layout.
  bool board_ok() const { return board_ok_; }
  // nullptr, or why the signal chain's configuration is unusable.
  const char* chain_error() const { return chain_.config_error(); }
  // CAN telemetry as last encoded (the snapshot the frames were made from).
  const can::TelemetrySnapshot& telemetry() const { return snapshot_; }
  uint32_t can_tx_refused() const { return link_.stats().tx_refused; }
  // CAN controller restarts made after bus-off.
  uint32_t can_restarts() const { return link_.stats().restarts; }
  // The firmware's CAN link (commands, telemetry, bus-off restart, the
  // calibration service).
  const can::CanLink& can_link() const { return link_; }
  // Where a calibration written over CAN goes (the firmware's apply path,
  // all or nothing), and the one in force now.
  void set_calibration_apply(can::CalibrationApply apply_fn, void* context,
                             const Calibration& active) {
    link_.calibration().set_apply(apply_fn, context);
    link_.calibration().set_active(active);
  }
  // What the calibration checks (firmware/app) found, for HRG_STATUS.
  struct CalibrationFlags {
    bool withdrawn = false;        // the correction of the pickoffs was withdrawn
    bool damping_refuted = false;  // the damping model was refuted
    bool gap_refuted = false;      // the gap harmonic was refuted
  };
  void set_calibration_flags(const CalibrationFlags& f) { calibration_flags_ = f; }
  // The firmware's own readings for a calibration (HRG_CAL_READINGS): when
  // the next frame's telemetry starts a set of them, set them before it
  // (the encoder holds them for the set's pages).
  bool cal_readings_due() const { return telemetry_.cal_readings_due(); }
  void set_cal_readings(const can::FirmwareEstimates& e) { snapshot_.estimates = e; }

  // Task bodies (rows of kTasks).
  static void task_chain(Gyro& g);
  static void task_supervise(Gyro& g);
  static void task_identify(Gyro& g);
  static void task_output(Gyro& g);
  static void task_temperature(Gyro& g);
  static void task_solve(Gyro& g);
  static void task_telemetry(Gyro& g);
  static void task_commands(Gyro& g);

  // CAN commands: accepted, refused (any reason), last result.
  uint32_t commands_accepted() const { return link_.stats().commands_accepted; }
  uint32_t commands_refused() const { return link_.stats().commands_refused; }

 private:
  void on_mode_change(Mode from, Mode to);
  // Do no harm: updates status_.compensation_valid from the check windows.
  void check_model();
  bool in_bands() const;
  void step_mode_progress(const WindowDecision& d);
  void apply(const can::Command& c);

  hal::Board& board_;
  SignalChain& chain_;
  ResonatorIdentifier& identifier_;
  GyroConfig cfg_;
  hal::MonotonicClock& exec_timer_;
  Executive<Gyro, kTaskCount> exec_;
  ModeMachine mode_;
  FaultMonitor monitor_;
  WindowScheduler scheduler_;
  AngleOutput output_;
  GyroStatus status_{};
  PumpEdgeCheck pump_edge_;
  can::TelemetryEncoder telemetry_{can::TelemetryConfig::defaults(), kBaseRateHz};
  can::TelemetrySnapshot snapshot_{};
  CalibrationFlags calibration_flags_{};
  can::EnvelopeReference envelope_;
  can::CanLink link_;
  ChainCommands commands_{};
  std::array<hal::q31_t, kBlockFrames * hal::kAdcChannels> adc_{};
  std::array<hal::q31_t, kBlockFrames * hal::kDacChannels> dac_{};
  uint64_t expected_block_ns_ = 0;
  uint64_t block_ns_ = 0;
  uint32_t adc_clipped_ = 0;
  uint32_t progress_frames_ = 0;  // frames the current mode's exit condition has held
  bool adc_stuck_ = false;
  bool dac_error_ = false;
  uint32_t pattern_hold_frames_ = 0;
  bool host_pattern_ = false;
  bool compensation_ready_ = false;
  bool control_drift_withheld_ = false;  // check_model(): D_Phi not applied
  uint32_t checks_seen_ = 0;
  uint32_t checks_passed_ = 0;
  uint32_t failed_before_restart_ = 0;  // model_checks_failed when the campaign restarted
  double host_pattern_target_rad_ = 0.0;
  bool enable_written_ = false;
  bool board_ok_ = true;
  Mode last_mode_ = Mode::power_up;
};

// The task table. The fast chain first (ADC -> demod -> PLL/AGC/quadrature ->
// DAC): the DAC block written in this frame is output one block later, so
// anything before it would add a frame of latency to the loops. Then decide
// (supervise), then use the fresh sample (identify, output); the slow tasks last
// (the temperature sensor at 10 Hz: the resonator's temperature moves over
// seconds, and a sensor read may be a bus transaction).
inline constexpr std::array<Task<Gyro>, Gyro::kTaskCount> kGyroTasks{{
    // name        function                 rate_hz      budget_ns
    {"chain", &Gyro::task_chain, kBaseRateHz, 400'000},
    {"supervise", &Gyro::task_supervise, kBaseRateHz, 40'000},
    {"identify", &Gyro::task_identify, kBaseRateHz, 40'000},
    {"output", &Gyro::task_output, kBaseRateHz, 20'000},
    {"temperature", &Gyro::task_temperature, 100, 10'000},
    {"solve", &Gyro::task_solve, 10, 200'000},
    {"telemetry", &Gyro::task_telemetry, kBaseRateHz, 60'000},
    {"commands", &Gyro::task_commands, 100, 30'000},
}};
static_assert(all_rates_divide(kGyroTasks, kBaseRateHz),
              "every task rate must divide the base rate");
static_assert(total_budget_ns(kGyroTasks) < 1'000'000'000ull / kBaseRateHz,
              "the worst frame's budgets must fit in the base period");

}  // namespace hrg::fw
