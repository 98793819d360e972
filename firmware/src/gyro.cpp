// SPDX-License-Identifier: MIT
#include "firmware/gyro.hpp"

#include <array>
#include <cmath>

namespace hrg::fw {

Gyro::Gyro(hal::Board& board, SignalChain& chain, ResonatorIdentifier& identifier,
           hal::MonotonicClock& timer, Pacing pacing, const GyroConfig& cfg)
    : board_(board),
      chain_(chain),
      identifier_(identifier),
      cfg_(cfg),
      exec_timer_(timer),
      exec_(kGyroTasks, kBaseRateHz, board.clock, timer, pacing),
      monitor_(cfg.monitor),
      scheduler_(cfg.windows),
      output_(cfg.angular_gain, 1.0 / kBaseRateHz),
      pump_edge_(cfg.pump_edge),
      envelope_(cfg.envelope),
      link_(board.can, kCanRestartRuns, cfg.calibration_service) {
  monitor_.set_amplitude_set_v(cfg_.amplitude_set_v);
  const hal::ConverterInfo adc = board.adc.info();
  const hal::ConverterInfo dac = board.dac.info();
  // The buffers are sized at compile time; a board with another layout is
  // refused (the firmware stays in power_up with drives off).
  // An unusable chain configuration (chain_error() names it) is refused the
  // same way.
  board_ok_ = adc.block_frames == kBlockFrames && dac.block_frames == kBlockFrames &&
              adc.sample_rate_hz == kAdcRateHz && chain.config_error() == nullptr;
  block_ns_ = 1'000'000'000ull / kBaseRateHz;
  (void)board_.excitation_enable.write(false);
  // Receive only the command range (where the controller can filter).
  (void)link_.init();
}

void Gyro::command_pattern_angle(double theta_rad) {
  host_pattern_ = true;
  host_pattern_target_rad_ = theta_rad;
}

void Gyro::release_pattern() { host_pattern_ = false; }

void Gyro::task_chain(Gyro& g) {
  uint64_t t_first_ns = 0;
  uint32_t clipped = 0;
  const uint64_t t_wait = g.exec_timer_.now_ns();
  const hal::Status st = g.board_.adc.read_block(g.adc_, t_first_ns, clipped);
  g.status_.adc_wait_ns += g.exec_timer_.now_ns() - t_wait;
  if (st != hal::Status::ok) {
    ++g.status_.adc_errors;
    return;
  }
  if (g.expected_block_ns_ != 0 && t_first_ns > g.expected_block_ns_) {
    g.status_.adc_missed_blocks +=
        static_cast<uint32_t>((t_first_ns - g.expected_block_ns_ + g.block_ns_ / 2) / g.block_ns_);
  }
  g.expected_block_ns_ = t_first_ns + g.block_ns_;
  g.adc_clipped_ = clipped;
  g.adc_stuck_ = adc_block_stuck(g.adc_, hal::kAdcChannels);

  const ModePolicy& p = g.mode_.permissions();
  ChainCommands& c = g.commands_;
  c.pump_on = p.pump && g.board_ok_;
  c.forcers_on = p.forcers && g.board_ok_;
  c.ring_up = g.mode_.mode() == Mode::ring_up;
  c.amplitude_set_v = g.cfg_.amplitude_set_v;
  g.chain_.process(g.adc_, g.dac_, c, g.status_.chain);
  g.status_.chain.t_s = static_cast<double>(t_first_ns + g.block_ns_) * 1e-9;

  // The mode gate, independent of what the chain computed: drives that the
  // mode does not permit are written as zero.
  for (std::size_t i = 0; i < kBlockFrames; ++i) {
    if (!c.pump_on) g.dac_[i * hal::kDacChannels] = 0;
    if (!c.forcers_on) {
      g.dac_[i * hal::kDacChannels + 1] = 0;
      g.dac_[i * hal::kDacChannels + 2] = 0;
    }
  }
  const hal::Status dst = g.board_.dac.write_block(g.dac_);
  if (dst != hal::Status::ok) ++g.status_.dac_errors;
  g.dac_error_ = hal::is_fatal(dst);
  g.status_.excitation_on = c.pump_on || c.forcers_on;
  if (!c.pump_on) g.status_.chain.pump_v = 0.0;
  g.pump_edge_.add_row(g.status_.chain, c.pump_on, g.mode_.mode() == Mode::operate);
  g.status_.pump_edge = g.pump_edge_.status();
  if (g.enable_written_ != p.enable_line || g.exec_.tick() == 0) {
    (void)g.board_.excitation_enable.write(p.enable_line && g.board_ok_);
    g.enable_written_ = p.enable_line;
  }
  g.status_.enable_line = g.enable_written_ && g.board_ok_;
}

bool Gyro::in_bands() const {
  const ChainRecord& o = status_.chain;
  if (!o.locked || cfg_.amplitude_set_v <= 0.0 || o.wave.a_A_v <= 0.0) return false;
  const double amp_err = std::fabs(o.wave.a_A_v - cfg_.amplitude_set_v) / cfg_.amplitude_set_v;
  return amp_err < cfg_.amplitude_band &&
         std::fabs(o.wave.a_B_v / o.wave.a_A_v) < cfg_.quadrature_band;
}

void Gyro::step_mode_progress(const WindowDecision& d) {
  const ChainRecord& o = status_.chain;
  switch (mode_.mode()) {
    case Mode::power_up:
      if (board_ok_ && ++progress_frames_ >= cfg_.self_test_frames) {
        mode_.handle(Event::self_test_passed);
      }
      break;
    case Mode::ring_up:
      if (o.wave.a_A_v >= (1.0 - cfg_.amplitude_band) * cfg_.amplitude_set_v) {
        mode_.handle(Event::amplitude_reached);
      }
      break;
    case Mode::lock:
      progress_frames_ = in_bands() ? progress_frames_ + 1 : 0;
      if (progress_frames_ >= cfg_.settle_frames) mode_.handle(Event::loops_settled);
      break;
    case Mode::operate:
      if (d.open) mode_.handle(Event::window_open);
      break;
    case Mode::free_decay:
      if (d.close) mode_.handle(Event::window_close);
      break;
    case Mode::recover:
      progress_frames_ = in_bands() ? progress_frames_ + 1 : 0;
      if (progress_frames_ >= cfg_.reacquire_frames) mode_.handle(Event::reacquired);
      break;
    case Mode::fault:
      progress_frames_ = status_.faults == 0 ? progress_frames_ + 1 : 0;
      if (progress_frames_ >= cfg_.fault_hold_frames) mode_.handle(Event::fault_cleared);
      break;
    case Mode::safe: break;
  }
}

void Gyro::task_supervise(Gyro& g) {
  bool fault_in = false;
  (void)g.board_.fault_input.read(fault_in);
  g.status_.fault_input = fault_in;
  MonitorInputs in;
  in.amplitude_v = g.status_.chain.wave.a_A_v;
  in.pll_locked = g.status_.chain.locked;
  in.adc_clipped = g.adc_clipped_;
  in.adc_samples = static_cast<uint32_t>(g.adc_.size());
  in.adc_stuck = g.adc_stuck_;
  // In lockstep the task times are host times, not the target's: they are
  // reported, but a busy host must not fault the simulated gyro.
  in.recent_overruns = g.exec_.pacing() == Pacing::real_time ? g.exec_.recent_overrun_frames() : 0;
  in.external_fault = fault_in;
  in.dac_error = g.dac_error_;
  const uint16_t faults = g.monitor_.update(in, g.mode_.mode());
  g.status_.faults = faults;
  if (faults != 0 && g.mode_.mode() != Mode::fault && g.mode_.mode() != Mode::safe) {
    g.mode_.handle(Event::fault_detected, faults);
  }

  // Window schedule; a host pattern command has priority over the scheduler's.
  // Without identification there are no windows (the scheduler still counts
  // frames for the duty figure).
  WindowDecision d;
  if (g.cfg_.identify) {
    d = g.scheduler_.step(g.mode_.mode(), g.output_.theta_unwrapped_rad(),
                          g.output_.rate_rad_s() * -g.cfg_.angular_gain / 2.0,
                          g.identifier_.health());
  } else {
    (void)g.scheduler_.step(Mode::power_up, 0.0, 0.0, {});
  }
  const bool operating = g.mode_.mode() == Mode::operate;
  g.commands_.pattern_control = operating && (g.host_pattern_ || d.pattern_command);
  g.commands_.pattern_target_rad =
      g.host_pattern_ ? g.host_pattern_target_rad_ : d.pattern_target_rad;
  g.status_.pattern_control = g.commands_.pattern_control;

  if (faults == 0 || g.mode_.mode() == Mode::fault) g.step_mode_progress(d);
  const Mode now = g.mode_.mode();
  if (now != g.last_mode_) {
    g.on_mode_change(g.last_mode_, now);
    g.last_mode_ = now;
  }
  g.status_.mode = now;
}

void Gyro::on_mode_change(Mode from, Mode to) {
  progress_frames_ = 0;
  // The enable line follows the mode at once (the drives follow with the next block).
  const bool enable = policy(to).enable_line && board_ok_;
  (void)board_.excitation_enable.write(enable);
  enable_written_ = enable;
  if (to == Mode::free_decay) identifier_.begin_window(status_.chain.t_s);
  if (from == Mode::free_decay) {
    if (to == Mode::recover) {
      if (compensation_ready_ && !cfg_.continue_identification) {
        identifier_.end_check_window();
      } else {
        identifier_.end_window();
      }
    } else {
      identifier_.abort_window();
    }
  }
}

void Gyro::task_identify(Gyro& g) {
  if (g.mode_.mode() == Mode::free_decay) {
    g.identifier_.add_sample(g.status_.chain);
  } else if (g.mode_.mode() == Mode::operate && g.status_.excitation_on &&
             !g.status_.pattern_control && g.pattern_hold_frames_ == 0) {
    // D_Phi is estimated from the loops' effort while they hold the wave.
    g.identifier_.add_control_sample(g.status_.chain);
  }
}

void Gyro::task_output(Gyro& g) {
  const ChainRecord& o = g.status_.chain;
  // The output is held while the pattern is moved on purpose, and for a
  // short time after (the demodulator still shows the end of the move).
  const bool moving_on_purpose = g.status_.pattern_control || g.pattern_hold_frames_ > 0;
  if (g.status_.pattern_control) {
    g.pattern_hold_frames_ = kPatternHoldFrames;
  } else if (g.pattern_hold_frames_ > 0) {
    --g.pattern_hold_frames_;
  }
  if (moving_on_purpose) g.output_.rereference();
  const double ratio = o.wave.a_A_v > 0.0 ? o.wave.a_B_v / o.wave.a_A_v : 0.0;
  // The model is applied once the campaign has ended (conditioning and
  // coverage good): an early solution from a few windows at nearby angles
  // would add more error than it removes.
  g.check_model();
  const bool apply = g.cfg_.compensate_drift && g.status_.compensation_applied;
  double drift = apply ? g.identifier_.drift_rad_s(o.theta_A_rad, ratio, o.wave.E_v2) : 0.0;
  // The control loops drift the pattern only while they drive it.
  double control = 0.0;
  if (apply && g.cfg_.compensate_control_drift && g.status_.excitation_on) {
    control = g.identifier_.control_drift_rad_s(o);
  }
  // ... unless the readout's own pattern explains what its fits read.
  g.status_.control_drift_withheld_rad_s = g.control_drift_withheld_ ? control : 0.0;
  if (g.control_drift_withheld_) control = 0.0;
  drift += control;
  g.status_.control_drift_rad_s = control;
  const bool valid = g.mode_.permissions().output_valid && !moving_on_purpose;
  g.output_.update(o.theta_A_rad, drift, valid);
  GyroStatus& s = g.status_;
  s.drift_rad_s = drift;
  s.theta_unwrapped_rad = g.output_.theta_unwrapped_rad();
  s.out_angle_rad = g.output_.angle_rad();
  s.out_raw_angle_rad = g.output_.raw_angle_rad();
  s.out_rate_rad_s = g.output_.rate_rad_s();
  s.out_valid = g.output_.valid();
}

void Gyro::check_model() {
  const EstimatorHealth h = identifier_.health();
  status_.readout_damping_sigmas = h.readout_damping_sigmas;
  if (!compensation_ready_) {
    if (!(cfg_.identify ? scheduler_.campaign_done() : h.solved)) {
      status_.compensation_reasons = reason_bit(CompensationReason::not_in_force);
      return;
    }
    compensation_ready_ = true;
    checks_seen_ = h.windows_checked;  // the campaign's own windows prove nothing
  }
  if (h.windows_checked != checks_seen_) {
    checks_seen_ = h.windows_checked;
    // Two-sided: the check window's residual against the fit's own residual.
    if (h.window_misfit <= cfg_.max_window_misfit && h.window_misfit >= cfg_.min_window_misfit) {
      ++checks_passed_;
    } else {
      ++status_.model_checks_failed;
    }
  }
  // In force from the end of the campaign (its conditioning and coverage
  // are good) until a check window disagrees; then withdrawn for good.
  // Reported valid only once a check window (on a still base first, where
  // a fit made while turning is most likely wrong) agreed with it.
  status_.compensation_applied = status_.model_checks_failed == failed_before_restart_;
  const bool checked = cfg_.identify && cfg_.windows.check_period_frames != 0;
  // A control-loop drift once measured and added, no longer added, leaves
  // the output short of it: not one the firmware stands behind while so.
  const bool control_lost = cfg_.compensate_control_drift && h.control_drift_lost;
  const bool readout_in_damping = cfg_.max_readout_damping_sigmas > 0.0 &&
                                  h.readout_damping_sigmas > cfg_.max_readout_damping_sigmas;
  // D_Phi's fits read the measured amplitude and angle: a readout pattern
  // the firmware sees makes their estimate one it cannot stand behind.
  const bool readout_pattern = cfg_.max_readout_pattern_sigmas > 0.0 &&
                               h.readout_pattern_sigmas > cfg_.max_readout_pattern_sigmas;
  control_drift_withheld_ =
      cfg_.compensate_control_drift && (readout_in_damping || readout_pattern);
  // A phase lag left in the readout drifts the output by 2 nu phi, which
  // the model does not have (EstimatorHealth::readout_phase_drift_share).
  const bool phase_drift = cfg_.max_readout_phase_sigmas > 0.0 &&
                           h.readout_phase_sigmas > cfg_.max_readout_phase_sigmas &&
                           h.readout_phase_drift_share > cfg_.max_readout_phase_drift_share;
  uint8_t why = 0;
  const auto add = [&why](bool c, CompensationReason r) {
    if (c) why = static_cast<uint8_t>(why | reason_bit(r));
  };
  add(!status_.compensation_applied, CompensationReason::check_failed);
  add(checked && checks_passed_ == 0, CompensationReason::not_checked);
  add(status_.pump_edge.verdict == PumpEdgeVerdict::step, CompensationReason::pump_edge_step);
  add(control_lost, CompensationReason::control_drift_lost);
  add(readout_in_damping, CompensationReason::readout_in_damping);
  add(control_drift_withheld_, CompensationReason::control_drift_withheld);
  add(phase_drift, CompensationReason::readout_phase_drift);
  status_.compensation_reasons = why;
  // A withheld D_Phi leaves the output short of a drift only while the
  // pump's part was in use; otherwise it withholds nothing measured.
  const auto others =
      static_cast<uint8_t>(why & ~reason_bit(CompensationReason::control_drift_withheld));
  status_.compensation_valid = others == 0 && !(control_drift_withheld_ && h.pump_drift_in_use);
}

void Gyro::restart_identification() {
  scheduler_ = WindowScheduler(cfg_.windows);
  compensation_ready_ = false;
  checks_passed_ = 0;
  failed_before_restart_ = status_.model_checks_failed;
  status_.compensation_applied = false;
  status_.compensation_valid = false;
  status_.compensation_reasons = reason_bit(CompensationReason::not_in_force);
  control_drift_withheld_ = false;
}

void Gyro::task_temperature(Gyro& g) {
  double temp_c = 0.0;
  const hal::Status st = g.board_.temperature.read(temp_c);
  GyroStatus& s = g.status_;
  if (st == hal::Status::ok) {
    s.temp_c = temp_c;
    s.temp_valid = true;
  } else if (!hal::is_retryable(st)) {
    // A failed read is not a temperature: the model falls back to its
    // reference temperature rather than use a stale one.
    if (st != hal::Status::closed) ++s.temp_errors;
    s.temp_valid = false;
  }
  g.identifier_.set_temperature_c(s.temp_c, s.temp_valid);
}

void Gyro::task_solve(Gyro& g) {
  if (g.cfg_.identify) g.identifier_.solve();
}

void Gyro::task_telemetry(Gyro& g) {
  const GyroStatus& st = g.status_;
  can::TelemetrySnapshot& s = g.snapshot_;
  g.envelope_.after_block(st.chain.t_s, st.chain.nco_phase, st.excitation_on);
  const can::EnvelopeRow row = g.envelope_.row(st.chain.quad_v.cx, st.chain.quad_v.sx,
                                               st.chain.quad_v.cy, st.chain.quad_v.sy);
  s.cx_v = row.cx_v;
  s.sx_v = row.sx_v;
  s.cy_v = row.cy_v;
  s.sy_v = row.sy_v;
  s.row_t_s = row.t_s;
  s.row_exc = row.exc;
  s.row_ready = g.envelope_.ready();
  s.f_ref_hz = g.envelope_.f_ref_hz();
  s.theta_a_rad = st.theta_unwrapped_rad;
  s.output_angle_rad = st.out_angle_rad;
  s.pll_freq_hz = st.chain.pll_freq_hz;
  s.pll_locked = st.chain.locked;
  s.quad_effort = st.chain.quad_effort;
  s.pump_v = st.chain.pump_v;
  s.row_pump_v = st.chain.pump_seen_v;
  s.agc_setpoint_v = g.cfg_.amplitude_set_v;
  s.temp_c = st.temp_valid ? st.temp_c : 0.0;
  s.mode = st.mode;
  s.exc_on = st.excitation_on;
  s.exc_line = st.enable_line;
  s.fault_input = st.fault_input;
  s.ident_active = g.cfg_.identify && !g.scheduler_.campaign_done();
  s.comp_valid = st.compensation_valid;
  s.comp_reasons = st.compensation_reasons;
  s.readout_damping_sigmas = st.readout_damping_sigmas;
  s.cal_withdrawn = g.calibration_flags_.withdrawn;
  s.cal_damping_refuted = g.calibration_flags_.damping_refuted;
  s.cal_gap_refuted = g.calibration_flags_.gap_refuted;
  s.faults = static_cast<uint16_t>(st.faults | g.mode_.faults());
  const Identification id = g.identifier_.identification();
  s.nu_per_s = id.p[0];
  s.dnu_c_per_s = id.p[1];
  s.dnu_s_per_s = id.p[2];
  s.dw_c_rad_s = id.p[3];
  s.dw_s_rad_s = id.p[4];
  const EstimatorHealth h = g.identifier_.health();
  s.cond_log10 = h.condition > 0.0 ? std::log10(h.condition) : 0.0;
  s.coverage = h.coverage;
  s.windows = g.scheduler_.windows();
  s.est_valid = id.valid;
  uint32_t overruns = 0;
  uint64_t busy_ns = 0;
  for (const auto& t : g.exec_.task_stats()) {
    overruns += t.overruns;
    busy_ns += t.total_ns;
  }
  const FrameStats& f = g.exec_.frame_stats();
  s.overruns = overruns;
  s.missed_ticks = f.missed_frames;
  s.max_frame_us = f.max_frame_ns / 1000;
  s.cpu_load_pct =
      f.frames == 0
          ? 0.0
          : 100.0 * static_cast<double>(busy_ns) /
                (static_cast<double>(f.frames) * static_cast<double>(g.exec_.period_ns()));
  s.angular_gain = g.cfg_.angular_gain;
  s.window_period_s = static_cast<double>(g.cfg_.windows.period_frames) / kBaseRateHz;
  s.window_length_s = static_cast<double>(g.cfg_.windows.length_frames) / kBaseRateHz;
  s.can = g.board_.can.counters();
  s.can_state = g.board_.can.state();

  std::array<hal::CanFrame, can::kTelemetryCount> frames{};
  const std::size_t n = g.telemetry_.tick(s, frames);
  // A full queue drops the frame (counted by the driver and the link); the
  // executive never waits for the bus.
  g.link_.send(std::span<const hal::CanFrame>(frames.data(), n));
}

void Gyro::task_commands(Gyro& g) {
  // Bus-off recovery is the link's (one policy): the controller stays off the
  // bus for kCanRestartRuns runs, then is restarted; nothing else would bring
  // it back. Nothing is received while it is off.
  const bool bus_off = g.board_.can.state() == hal::CanState::bus_off;
  g.link_.service();
  if (bus_off) return;
  // The calibration service's clock: milliseconds of base frames.
  const auto now_ms = static_cast<uint32_t>(g.exec_.frame_stats().frames * 1000u / kBaseRateHz);
  g.link_.tick_calibration(now_ms, g.mode_.mode());
  can::ControllerView view;
  view.faults = static_cast<uint16_t>(g.status_.faults | g.mode_.faults());
  view.fault_input = g.status_.fault_input;
  view.ident_active = g.cfg_.identify && !g.scheduler_.campaign_done();
  for (uint32_t n = 0; n < kCommandsPerRun; ++n) {
    // Each command is validated against the state the previous one left.
    view.mode = g.mode_.mode();
    view.agc_setpoint_v = g.cfg_.amplitude_set_v;
    can::Command cmd;
    // Refused commands and every calibration frame are answered by the link;
    // a calibration block is applied there (service mode, between blocks).
    if (!g.link_.poll(view, cmd, now_ms, static_cast<uint32_t>(g.exec_timer_.now_ns()))) break;
    g.apply(cmd);
    if (cmd.id == can::Cmd::status_request) {
      hal::CanFrame status;
      g.telemetry_.encode_now(can::Tm::status, g.snapshot_, status);
      g.link_.send({&status, 1});
    }
  }
}

void Gyro::apply(const can::Command& c) {
  switch (c.id) {
    case can::Cmd::set_mode:
      // The host may stop the drives (safe) or ask for a ring-up from safe
      // (a restart through power_up) or from fault (a retry now); the
      // validator refuses every other target.
      if (c.mode == Mode::safe) {
        mode_.handle(Event::command_safe);
      } else if (c.mode == Mode::ring_up) {
        mode_.handle(mode_.mode() == Mode::fault ? Event::fault_cleared : Event::command_restart);
      }
      break;
    case can::Cmd::ident:
      cfg_.identify = c.ident_start;
      // A new campaign from scratch (no heap: the scheduler is rebuilt in place).
      if (c.ident_start) scheduler_ = WindowScheduler(cfg_.windows);
      break;
    case can::Cmd::window:
      cfg_.windows.period_frames = static_cast<uint32_t>(c.window_period_s * kBaseRateHz + 0.5);
      cfg_.windows.length_frames = static_cast<uint32_t>(c.window_length_s * kBaseRateHz + 0.5);
      scheduler_.set_timing(cfg_.windows.length_frames, cfg_.windows.period_frames);
      break;
    case can::Cmd::agc:
      cfg_.amplitude_set_v = c.agc_setpoint_v;
      monitor_.set_amplitude_set_v(c.agc_setpoint_v);
      break;
    case can::Cmd::status_request: break;
  }
}

}  // namespace hrg::fw
