// SPDX-License-Identifier: MIT
#pragma once

#include "firmware/app/calibration_guard.hpp"
#include "firmware/app/firmware_config.hpp"
#include "firmware/app/self_calibration_rounds.hpp"
#include "firmware/dsp_chain_port.hpp"
#include "firmware/estimator_port.hpp"
#include "firmware/gyro.hpp"
#include "hal/board.hpp"

namespace hrg::fw::app {

// The firmware assembled on a board: the signal chain over dsp::Chain, the
// estimator and the gyro (executive, modes, windows, output, CAN) that runs
// them. The only place where the parts are put together; the main job
// (hrg sim), hrg-board and the audit's firmware campaign all build this.
// Large (the chain holds its filters): a board places it statically, a host
// on the heap. Allocates nothing itself.
class Firmware {
 public:
  // `timer` times the tasks (the board clock in real time, a host clock in
  // lockstep).
  Firmware(hal::Board& board, hal::MonotonicClock& timer, Pacing pacing, const FirmwareConfig& cfg)
      : cfg_(cfg),
        chain_(cfg.chain),
        estimator_(cfg.estimator),
        gyro_(board, chain_, estimator_, timer, pacing, cfg.gyro),
        guard_(cfg.gyro.min_window_misfit, cfg.gyro.max_window_misfit) {
    calibration_ok_ = apply_calibration(cfg.calibration, CalibrationSource::file);
    // A calibration written over CAN takes the same path.
    gyro_.set_calibration_apply(&Firmware::apply_from_can, this, cfg_.calibration);
  }
  Firmware(const Firmware&) = delete;
  Firmware& operator=(const Firmware&) = delete;

  // nullptr when the firmware can drive the resonator, else why it keeps the
  // drives off (an unusable chain configuration, a board whose converters
  // do not match the firmware's block layout).
  const char* error() const {
    if (const char* e = chain_.error()) return e;
    if (!calibration_ok_) return "the calibration is out of range or does not fit the chain";
    return gyro_.board_ok() ? nullptr
                            : "the board's converters do not match the firmware's block layout";
  }

  // Puts `cal` in force: the pickoff-map inverse and the feedthrough removal
  // on the chain's demodulated quadratures. All or nothing: false (the one in
  // force stays) when a field is out of range or a coefficient does not fit
  // the chain's Q formats. The one way a calibration enters the firmware
  // (file at start, online self-calibration, CAN block): it is then on trial
  // until the next check window judges it (CalibrationGuard), and withdrawn
  // if that one disagrees.
  bool apply_calibration(const Calibration& cal, CalibrationSource source);
  // The calibration in force (the identity after a withdrawal) and its trial.
  const Calibration& calibration() const { return cfg_.calibration; }
  const CalibrationStatus& calibration_status() const { return guard_.status(); }

  void run_frame() {
    // Once per set of HRG_CAL_READINGS (0.7 s at the default rate), not per
    // frame: the referral to the raw pickoffs costs four sines.
    if (gyro_.cal_readings_due()) gyro_.set_cal_readings(estimates());
    gyro_.run_frame();
    judge_calibration();
    if (cfg_.online_pickoff_calibration) self_calibrate();
  }
  const SelfCalibrationStatus& self_calibration() const { return self_cal_.status(); }
  // The pickoff map a board keeps for the next power-up
  // (SelfCalibrationRounds::map_to_keep; the map in force while the online
  // self-calibration is off, and after a withdrawal of its rounds the map
  // the withdrawal left: the one before them where they held nothing).
  est::PickoffMap pickoff_map_to_keep() const;
  // The firmware's own readings of what a calibration holds, now: the
  // switch-off step check's residual referred to the raw pickoffs through
  // the calibration in force (its edges were read through it: a change of
  // it resets the check), and the damping model check's thermal damping.
  // What HRG_CAL_READINGS sends and hrg sim writes into its recording.
  can::FirmwareEstimates estimates() const;
  Gyro& gyro() { return gyro_; }
  const Gyro& gyro() const { return gyro_; }
  const DspChainPort& chain() const { return chain_; }
  const EstimatorPort& estimator() const { return estimator_; }
  const FirmwareConfig& config() const { return cfg_; }

 private:
  // Withdraws the calibration in force when its check window disagreed,
  // takes out its damping model or its gap harmonic when their checks
  // refute them.
  void judge_calibration();
  // A calibration's pickoff map `withdrawn` left the chain: the
  // self-calibration's windows re-referred to the raw pickoffs.
  void refer_self_calibration_to_raw(const est::PickoffMap& withdrawn);
  void judge_calibration_parts();
  // Puts the parts of `cal` beyond the chain in force: the resonator model
  // (estimator regressors and drift), the known gap harmonic, and, when the
  // electronics correction changed, a fresh switch-off step check.
  void put_in_force(const Calibration& cal, bool electronics_changed);
  // Folds a fresh, significant self-calibration estimate into the
  // correction, or withdraws the rounds when their model is refuted
  // (SelfCalibrationRounds), and starts the identification again.
  void self_calibrate();
  // Puts the self-calibration's `d` in force: true when the chain took it.
  bool put_self_calibration_in_force(const SelfCalibrationDecision& d);
  // The estimator's check windows count (the campaign is over, or none runs).
  bool checking() const;

  FirmwareConfig cfg_;
  DspChainPort chain_;
  EstimatorPort estimator_;
  Gyro gyro_;
  CalibrationGuard guard_;
  SelfCalibrationRounds self_cal_{};
  int self_cal_samples_seen_ = 0;
  bool calibration_ok_ = true;

  static bool apply_from_can(void* self, const Calibration& cal) {
    return static_cast<Firmware*>(self)->apply_calibration(cal, CalibrationSource::can);
  }
};

}  // namespace hrg::fw::app
