// SPDX-License-Identifier: MIT
// The main job's runner: the firmware (firmware/app) on the simulated target,
// in lockstep or paced in real time, with faults injected through the
// target's back door and one telemetry row per 1 / telemetry_hz.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "can/candump_log.hpp"
#include "dsp/demodulator.hpp"
#include "firmware/app/firmware.hpp"
#include "hal/linux/linux_clock.hpp"
#include "hal/linux/realtime.hpp"
#include "sim_target/control.hpp"
#include "sim_run/console.hpp"
#include "sim_run/run.hpp"

namespace hrg::sim_run {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kRadSToDph = 180.0 / kPi * 3600.0;

// The true state half-way between two instants (slow quantities, linear).
sim::TrueState midpoint(const sim::TrueState& a, const sim::TrueState& b) {
  sim::TrueState m = a;
  m.t_s = 0.5 * (a.t_s + b.t_s);
  m.pattern_angle_rad = 0.5 * (a.pattern_angle_rad + b.pattern_angle_rad);
  m.input_angle_rad = 0.5 * (a.input_angle_rad + b.input_angle_rad);
  m.energy_v2 = 0.5 * (a.energy_v2 + b.energy_v2);
  m.a_A_v = 0.5 * (a.a_A_v + b.a_A_v);
  m.a_B_v = 0.5 * (a.a_B_v + b.a_B_v);
  m.rate_rad_s = 0.5 * (a.rate_rad_s + b.rate_rad_s);
  m.temp_c = 0.5 * (a.temp_c + b.temp_c);
  return m;
}

// The boards and clocks the firmware runs on: in lockstep the simulated
// board's clock paces (it returns at once) and a host clock times the tasks;
// in real time CLOCK_MONOTONIC does both, with the simulated converters
// behind it.
struct Rig {
  explicit Rig(hal::Board& sim) : sim_board(sim) {}
  HostClock host_timer;
  hal::linux_board::LinuxClock rt_clock;
  hal::Board& sim_board;
  hal::Board rt_board{sim_board.adc,         sim_board.dac, sim_board.excitation_enable,
                      sim_board.fault_input, sim_board.can, rt_clock,
                      sim_board.temperature};
};

std::unique_ptr<fw::app::Firmware> build_firmware(const RunConfig& job, Rig& rig,
                                                  const RunOptions& opt, RunResult& r) {
  r.real_time = opt.real_time;
  if (opt.real_time) {
    hal::linux_board::RealtimeRequest req;
    req.priority = opt.rt_priority;
    char buf[200];
    r.realtime_setup =
        hal::linux_board::describe(hal::linux_board::setup_realtime(req), buf, sizeof buf);
  }
  // The firmware is large (the chain holds its filters): on the heap here,
  // statically allocated on a board.
  auto firmware = opt.real_time
                      ? std::make_unique<fw::app::Firmware>(rig.rt_board, rig.rt_clock,
                                                            fw::Pacing::real_time, job.firmware)
                      : std::make_unique<fw::app::Firmware>(rig.sim_board, rig.host_timer,
                                                            fw::Pacing::lockstep, job.firmware);
  if (const char* err = firmware->chain().error())
    throw std::invalid_argument(std::string("signal chain configuration: ") + err);
  if (const char* err = firmware->error()) throw std::invalid_argument(err);
  return firmware;
}

// Applies the faults due by time t_s through the target's back door.
void inject_faults(const RunConfig& job, double t_s, std::size_t& next, sim::SimTarget& target,
                   RunResult& r) {
  while (next < job.faults.size() && job.faults[next].t_s <= t_s) {
    const FaultEvent& e = job.faults[next++];
    switch (e.kind) {
      case FaultEvent::Kind::adc_stuck: target.set_adc_stuck(e.channel, e.on); break;
      case FaultEvent::Kind::adc_saturated: target.set_adc_saturated(e.channel, e.on); break;
      case FaultEvent::Kind::dac_dead: target.set_dac_dead(e.channel, e.on); break;
      case FaultEvent::Kind::fault_input: target.set_fault_input(e.on); break;
      case FaultEvent::Kind::can_bus_off:
        target.can().force_bus_off();
        r.t_can_back_s = -1.0;
        break;
    }
  }
}

// Mode changes, faults, convergence and the CAN's return after a bus-off.
void track_events(const fw::Gyro& gyro, sim::SimTarget& target, fw::Mode& last_mode, RunResult& r) {
  const fw::GyroStatus& st = gyro.status();
  const double t_s = st.chain.t_s;
  if (st.mode != last_mode) {
    ++r.mode_changes;
    if ((st.mode == fw::Mode::fault || st.mode == fw::Mode::safe) && r.t_first_fault_s < 0) {
      r.t_first_fault_s = t_s;
    }
    if (st.mode == fw::Mode::operate && r.t_first_fault_s >= 0 && r.t_back_operate_s < 0) {
      r.t_back_operate_s = t_s;
    }
    last_mode = st.mode;
  }
  r.faults_seen = static_cast<uint16_t>(r.faults_seen | st.faults);
  if (r.t_converged_s < 0 && gyro.scheduler().campaign_done()) r.t_converged_s = t_s;
  if (st.mode == fw::Mode::operate && !r.reached_operate) {
    r.reached_operate = true;
    r.t_operate_s = t_s;
  }
  if (r.t_can_back_s < 0 && !target.can().sent().empty() &&
      target.can().counters().bus_off_events > 0) {
    r.t_can_back_s = t_s;
  }
}

// The bench's rate table and chamber on the bus: a LAB_TABLE frame with the
// input rate and temperature a recording row's envelope saw, logged in the
// frame the firmware queues that row. The bus sends the row one frame later,
// so a reader pairs each row with the latest LAB_TABLE before it.
struct LabTable {
  uint64_t period_frames = 1;  // the firmware's recording row period
  uint8_t seq = 0;
};

// Counts (and logs, when asked) the frames the firmware put on the bus.
void drain_can(sim::SimTarget& target, can::CandumpLogWriter* log, double t_s, RunResult& r) {
  auto& bus = target.can();
  if (log) {
    for (const auto& f : bus.sent())
      log->write(f, static_cast<uint64_t>(t_s * 1e9));
  }
  r.can_frames += bus.sent().size();
  bus.clear_sent();
}

// Telemetry rows stamped at the centre of the demodulator's window, where
// the envelope is: the NCO's offset from the fixed reference and the true
// state at the last three block ends, and whether the drive was off long
// enough that the row's whole averaging span is free of it.
class RowStamper {
 public:
  // The demodulator's output describes the envelope at the centre of its
  // window, dsp::kDecimatorOrder / 2 blocks before the block end (within a
  // sample, dsp::decimator_group_delay_samples): half-way between the states
  // kCentre and kCentre + 1 blocks back.
  static constexpr std::size_t kCentre = dsp::kDecimatorOrder / 2;
  static constexpr std::size_t kHistory = kCentre + 2;

  explicit RowStamper(const RunConfig& job) : f_ref_hz_(job.firmware.chain.f_center_hz) {
    // The simulated DAC's own latency: the truth, not the firmware's layout.
    drive_free_blocks_ = fw::app::drive_free_blocks(
        job.firmware.chain, static_cast<double>(job.sim.dac.latency_samples));
    off_blocks_ = drive_free_blocks_;
  }

  // `stamped`: a row will read this block's state (it lands at kCentre or
  // kCentre + 1 blocks back at a row); the others skip the true state and
  // the reference phase, which cost more than the rest of the job loop.
  void after_block(const fw::app::Firmware& firmware, const sim::SimTarget& target, bool stamped) {
    const fw::GyroStatus& st = firmware.gyro().status();
    off_blocks_ = st.excitation_on ? 0 : off_blocks_ + 1;
    for (std::size_t i = kHistory - 1; i > 0; --i) {
      ref_offset_[i] = ref_offset_[i - 1];
      truth_[i] = truth_[i - 1];
    }
    ++blocks_;
    if (!stamped) return;
    // NCO phase at the first sample after this block (time t_s) against the
    // fixed reference 2 pi f_ref t.
    const double nco_cycles = static_cast<double>(firmware.chain().chain().nco_phase()) * 0x1p-32;
    const double ref_cycles = std::fmod(f_ref_hz_ * st.chain.t_s, 1.0);
    ref_offset_[0] = 2.0 * kPi * std::remainder(nco_cycles - ref_cycles, 1.0);
    truth_[0] = target.true_state();
  }
  // Whether frame k's block is read by a row taken every row_every frames.
  static bool stamped(uint64_t k, uint64_t row_every) {
    return (k + kCentre) % row_every == 0 || (k + kCentre + 1) % row_every == 0;
  }

  // Rows start once the history is full.
  bool history_full() const { return blocks_ >= kHistory; }
  // Stamped at the block end instead of the filter's centre, a rate ramp of
  // 10 deg/s^2 puts a 0.015 deg/s error (sinc^3 figure) into the input rate
  // the envelope saw, which the audit takes for a pickoff gain mismatch.
  sim::TrueState truth() const { return midpoint(truth_[kCentre], truth_[kCentre + 1]); }
  double ref_offset_rad() const {
    return ref_offset_[kCentre] +
           0.5 * std::remainder(ref_offset_[kCentre + 1] - ref_offset_[kCentre], 2.0 * kPi);
  }
  bool drive_free() const { return off_blocks_ >= drive_free_blocks_; }

 private:
  double f_ref_hz_;
  uint64_t drive_free_blocks_ = 0;
  uint64_t off_blocks_ = 0;  // blocks since the excitation was last on
  uint64_t blocks_ = 0;
  double ref_offset_[kHistory] = {};
  sim::TrueState truth_[kHistory];
};

// Angles are compared from the first valid output on.
struct AngleReference {
  bool set = false;
  double true_rad = 0.0, out_rad = 0.0, raw_rad = 0.0;
};

void record_row(RunResult& r, const RunConfig& job, const fw::Gyro& g, const RowStamper& stamp,
                const AngleReference& ref) {
  const fw::GyroStatus& st = g.status();
  const fw::ChainRecord& ch = st.chain;
  const sim::TrueState ts = stamp.truth();
  const double k = job.firmware.gyro.angular_gain;
  TelemetryRow row{};
  row.t_s = ts.t_s;
  // The chain demodulates against its NCO, whose phase the PLL moves every
  // block. The recording's cx..sy are against the fixed metadata reference
  // (ph = 2 pi f_ref t): x = Re((cx - i sx) e^(i ph_nco)) = Re((cx' - i sx')
  // e^(i ph)) with cx' - i sx' = (cx - i sx) e^(i (ph_nco - ph)).
  const double c = std::cos(stamp.ref_offset_rad());
  const double s = std::sin(stamp.ref_offset_rad());
  row.cx_v = ch.quad_v.cx * c + ch.quad_v.sx * s;
  row.sx_v = ch.quad_v.sx * c - ch.quad_v.cx * s;
  row.cy_v = ch.quad_v.cy * c + ch.quad_v.sy * s;
  row.sy_v = ch.quad_v.sy * c - ch.quad_v.cy * s;
  row.exc = stamp.drive_free() ? 0 : 1;
  row.excitation_cmd = st.excitation_on ? 1 : 0;
  row.pump_v = ch.pump_seen_v;  // the pump the row's quadratures saw
  // The temperature the firmware measured (the board's sensor, with its
  // resolution, noise and lag), as a gyro's own recording carries it; the
  // true one only when the board has no sensor.
  row.temp_c = st.temp_valid ? st.temp_c : ts.temp_c;
  row.rate_dps = ts.rate_rad_s / kDeg;
  row.pll_hz = ch.pll_freq_hz;
  row.quad_v = ch.wave.a_B_v;
  row.mode = static_cast<int>(st.mode);
  row.theta_deg = st.theta_unwrapped_rad / kDeg;
  row.out_angle_deg = (st.out_angle_rad - ref.out_rad) / kDeg;
  row.raw_angle_deg = (st.out_raw_angle_rad - ref.raw_rad) / kDeg;
  row.true_angle_deg = (ts.input_angle_rad - ref.true_rad) / kDeg;
  row.true_theta_deg = ts.pattern_angle_rad / kDeg;
  row.a_A_v = ch.wave.a_A_v;
  row.a_B_v = ch.wave.a_B_v;
  row.drift_model_dph = st.drift_rad_s / k * kRadSToDph;
  row.drift_control_dph = st.control_drift_rad_s / k * kRadSToDph;
  row.drift_withheld_dph = st.control_drift_withheld_rad_s / k * kRadSToDph;
  const double q = ts.a_A_v > 0 ? ts.a_B_v / ts.a_A_v : 0.0;
  row.drift_true_dph =
      true_drift_rad_s(job.sim.resonator, ts.pattern_angle_rad, q) / k * kRadSToDph;
  row.out_valid = st.out_valid ? 1 : 0;
  row.pattern_cmd = st.pattern_control ? 1 : 0;
  row.comp_valid = st.compensation_valid ? 1 : 0;
  row.comp_reasons = st.compensation_reasons;
  row.readout_damping_sigmas = st.readout_damping_sigmas;
  r.rows.push_back(row);
}

void summarise_executive(RunResult& r, const fw::Gyro& g) {
  const auto& ex = g.executive();
  for (std::size_t i = 0; i < fw::Gyro::kTaskCount; ++i) {
    const auto& t = ex.task(i);
    const auto& s = ex.task_stats()[i];
    TaskFigures f;
    f.name = t.name;
    f.rate_hz = t.rate_hz;
    f.budget_ns = t.budget_ns;
    f.min_ns = s.runs ? s.min_ns : 0;
    f.max_ns = s.max_ns;
    f.mean_ns = s.runs ? static_cast<double>(s.total_ns) / static_cast<double>(s.runs) : 0.0;
    f.overruns = s.overruns;
    f.slips = s.slips;
    f.runs = s.runs;
    r.tasks.push_back(f);
  }
  r.frames = ex.frame_stats();
}

// The model's bias uncertainty after each accepted solve (RunResult::convergence).
void record_convergence(const fw::app::Firmware& firmware, const RunConfig& job,
                        uint32_t& solves_seen, RunResult& r) {
  const fw::EstimatorPort& ident = firmware.estimator();
  if (ident.solves_accepted() == solves_seen) return;
  solves_seen = ident.solves_accepted();
  const est::ParamMatrix& c = ident.estimator().last_solution().covariance;
  const double var = c(est::kDnuC, est::kDnuC) + c(est::kDnuS, est::kDnuS);
  if (!(var > 0.0)) return;
  r.convergence.push_back({firmware.gyro().status().chain.t_s,
                           std::sqrt(var) / job.firmware.gyro.angular_gain * kRadSToDph});
}

// What the firmware identified, against the truth and the Cramer-Rao bound.
void summarise_identification(RunResult& r, const RunConfig& job,
                              const fw::app::Firmware& firmware) {
  const fw::Gyro& gyro = firmware.gyro();
  const fw::EstimatorPort& ident = firmware.estimator();
  r.excitation_off_fraction = gyro.scheduler().excitation_off_fraction();
  r.windows = gyro.scheduler().windows();
  r.windows_accepted = ident.windows_accepted();
  r.campaign_done = gyro.scheduler().campaign_done();
  r.identification = ident.identification();
  r.truth = true_parameters(job.sim.resonator);
  r.condition = ident.health().condition;
  r.coverage = ident.health().coverage;
  // Per-sample amplitude noise at the control rate: the pickoff noise (white,
  // sigma per ADC sample) mixed by 2 cos and low-passed to one sample per
  // block has the low-frequency density of a white sequence of variance
  // 2 sigma^2 / L at the block rate; a_A and a_B are unit-norm projections of
  // the x and y quadratures.
  const double adc_sigma_v =
      std::sqrt(0.5 * (job.sim.adc.noise_v_rms[0] * job.sim.adc.noise_v_rms[0] +
                       job.sim.adc.noise_v_rms[1] * job.sim.adc.noise_v_rms[1]));
  r.noise_sigma_v =
      adc_sigma_v * std::sqrt(2.0 / static_cast<double>(job.firmware.chain.block_frames));
  const est::ParamMatrix crb = ident.estimator().cramer_rao_bound(r.noise_sigma_v);
  for (int i = 0; i < est::kParams; ++i) {
    r.crb_sigma[static_cast<std::size_t>(i)] = crb(i, i) > 0.0 ? std::sqrt(crb(i, i)) : 0.0;
  }
}

// The calling thread's CPU time (runs in parallel threads each count their own).
// The pump fit's (eps_p, eps_q) = 2 (b1, b2) / b0 and their sigmas; zeros
// before the fit is valid.
std::array<double, 4> pump_eps_pq_sigma(const est::PumpDriftEstimator& pump) {
  Eigen::Vector2d g;
  Eigen::Matrix2d cov;
  const double b0 = pump.coefficients()(0);
  if (!(b0 > 0.0) || !pump.gap_fit(g, cov)) return {};
  const double k = 2.0 / b0;
  return {k * g(0), k * g(1), k * std::sqrt(std::max(cov(0, 0), 0.0)),
          k * std::sqrt(std::max(cov(1, 1), 0.0))};
}

uint64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1'000'000'000ull + static_cast<uint64_t>(ts.tv_nsec);
}

// The simulated target's share of the lockstep run by CPU time, robust to a
// loaded machine. The firmware times Adc::read_block on the host's steady
// clock, so a preemption inside a block counts as the target's and one
// outside it as the firmware's: with a few long preemptions per run the
// wall-clock share moves by several percent. Reading the thread's CPU clock
// around every block would settle that, but a read is a system call (2.6 us
// in a virtual machine, where a whole block takes about 3.5 us). So the run
// is cut into stretches of kStretchFrames blocks with one CPU-clock read
// each (about 0.6 % of the run): a stretch whose CPU time equals its wall time (to
// kPreemptedFraction) ran without being preempted, and there the steady clock's split between the
// target and the rest is a split of CPU time. The share is taken over those stretches; on an idle
// machine they are all of them.
class TargetShare {
 public:
  static constexpr uint64_t kStretchFrames = 128;
  static constexpr double kPreemptedFraction = 0.02;

  explicit TargetShare(const hal::MonotonicClock& wall) : wall_(wall) {}
  void start(uint64_t adc_wait_ns) { mark(adc_wait_ns); }
  // After the stretch's last frame.
  void close_stretch(uint64_t adc_wait_ns) {
    const uint64_t wall0 = wall_ns_, cpu0 = cpu_ns_, wait0 = wait_ns_;
    const uint64_t wall1 = wall_.now_ns();
    mark(adc_wait_ns);
    const auto wall = static_cast<double>(wall1 - wall0);
    const auto cpu = static_cast<double>(cpu_ns_ - cpu0);
    ++stretches_;
    if (wall - cpu > kPreemptedFraction * wall) return;
    ++kept_;
    kept_wall_ns_ += wall;
    kept_target_ns_ += static_cast<double>(wait_ns_ - wait0);
  }
  // Negative when no stretch ran unpreempted (or none closed). The CPU
  // interval holds one read more than the wall interval, never less.
  double share() const { return kept_wall_ns_ > 0 ? kept_target_ns_ / kept_wall_ns_ : -1.0; }
  double kept_fraction() const {
    return stretches_ ? static_cast<double>(kept_) / static_cast<double>(stretches_) : 0.0;
  }

 private:
  // The stretch's wall time starts after the CPU clock's read, so that the
  // read's own cost is not counted against the firmware.
  void mark(uint64_t adc_wait_ns) {
    cpu_ns_ = thread_cpu_ns();
    wall_ns_ = wall_.now_ns();
    wait_ns_ = adc_wait_ns;
  }
  const hal::MonotonicClock& wall_;
  uint64_t wall_ns_ = 0, cpu_ns_ = 0, wait_ns_ = 0;
  uint64_t stretches_ = 0, kept_ = 0;
  double kept_wall_ns_ = 0.0, kept_target_ns_ = 0.0;
};

// Speed of the run: wall and CPU time, the share spent in the simulation.
void summarise_speed(RunResult& r, const fw::Gyro& gyro, uint64_t frames, double wall_s,
                     double cpu_s, const TargetShare& share) {
  r.wall_s = wall_s;
  r.cpu_s = cpu_s;
  r.realtime_factor = r.wall_s > 0 ? r.sim_s / r.wall_s : 0.0;
  r.realtime_factor_cpu = r.cpu_s > 0 ? r.sim_s / r.cpu_s : 0.0;
  const auto adc_wait_ns = static_cast<double>(gyro.status().adc_wait_ns);
  r.adc_wait_mean_us = frames ? adc_wait_ns * 1e-3 / static_cast<double>(frames) : 0.0;
  r.sim_share = r.wall_s > 0 ? adc_wait_ns * 1e-9 / r.wall_s : 0.0;
  r.sim_share_cpu = share.share();
  r.share_stretches_kept = share.kept_fraction();
}

}  // namespace

RunResult run_simulation(const RunConfig& job, const RunOptions& opt) {
  RunResult r;
  // A simulated target of its own: runs in parallel threads share nothing.
  const auto own_target = std::make_unique<sim::SimTarget>();
  sim::SimTarget& target = *own_target;
  target.configure(job.sim);
  target.set_profiling(opt.profile);
  Rig rig(target.board());
  const std::unique_ptr<fw::app::Firmware> firmware = build_firmware(job, rig, opt, r);
  const fw::Gyro& gyro = firmware->gyro();
  std::unique_ptr<can::CandumpLogWriter> log;
  if (!opt.can_log.empty()) log = std::make_unique<can::CandumpLogWriter>(opt.can_log, "can0");

  const auto frames = static_cast<uint64_t>(std::llround(job.duration_s * fw::kBaseRateHz));
  const auto row_every =
      static_cast<uint64_t>(std::max(1.0, std::round(fw::kBaseRateHz / job.telemetry_hz)));
  r.rows.reserve(frames / row_every + 1);
  ProgressBar bar(static_cast<double>(frames), opt.progress);
  const auto wall0 = std::chrono::steady_clock::now();
  const uint64_t cpu0_ns = thread_cpu_ns();
  TargetShare share(rig.host_timer);
  share.start(gyro.status().adc_wait_ns);
  std::size_t next_fault = 0;
  fw::Mode last_mode = fw::Mode::power_up;
  uint32_t solves_seen = 0;
  RowStamper stamp(job);
  AngleReference ref;
  LabTable lab;
  lab.period_frames =
      fw::kBaseRateHz /
      fw::can::TelemetryConfig::defaults().rate_hz[static_cast<std::size_t>(fw::can::Tm::row)];
  const auto observe_every =
      static_cast<uint64_t>(std::max(1.0, std::round(opt.observe_every_s * fw::kBaseRateHz)));
  for (uint64_t k = 0; k < frames; ++k) {
    inject_faults(job, static_cast<double>(k) / fw::kBaseRateHz, next_fault, target, r);
    firmware->run_frame();
    if (!opt.real_time && (k + 1) % TargetShare::kStretchFrames == 0)
      share.close_stretch(gyro.status().adc_wait_ns);
    record_convergence(*firmware, job, solves_seen, r);
    const fw::GyroStatus& st = gyro.status();
    stamp.after_block(*firmware, target, RowStamper::stamped(k, row_every));
    track_events(gyro, target, last_mode, r);
    drain_can(target, log.get(), st.chain.t_s, r);
    if (log && stamp.history_full() && k % lab.period_frames == 0) {
      const sim::TrueState ts = stamp.truth();
      log->write(fw::can::encode_lab_table(ts.rate_rad_s / kDeg, ts.temp_c, lab.seq++),
                 static_cast<uint64_t>(st.chain.t_s * 1e9));
    }
    if (opt.observer && (k + 1) % observe_every == 0) opt.observer(*firmware, target);
    if (k % row_every != 0 || !stamp.history_full()) continue;
    if (!ref.set && st.out_valid) {
      ref = {true, stamp.truth().input_angle_rad, st.out_angle_rad, st.out_raw_angle_rad};
    }
    record_row(r, job, gyro, stamp, ref);
    if (opt.progress && k % 1000 == 0) {
      bar.update(static_cast<double>(k),
                 fmt("t=%.0f s %s", st.chain.t_s, fw::to_string(st.mode)).c_str());
    }
  }
  bar.finish();
  r.sim_s = job.duration_s;
  summarise_speed(r, gyro, frames,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count(),
                  static_cast<double>(thread_cpu_ns() - cpu0_ns) * 1e-9, share);
  r.final_mode = gyro.status().mode;
  r.compensation_valid = gyro.status().compensation_valid;
  r.compensation_applied = gyro.status().compensation_applied;
  r.model_checks_failed = gyro.status().model_checks_failed;
  const fw::EstimatorHealth health = firmware->estimator().health();
  r.last_window_misfit = health.window_misfit;
  r.compensation_reasons = gyro.status().compensation_reasons;
  r.readout_damping_sigmas = gyro.status().readout_damping_sigmas;
  r.readout_pattern_sigmas = health.readout_pattern_sigmas;
  r.readout_phase_sigmas = health.readout_phase_sigmas;
  r.readout_phase_drift_share = health.readout_phase_drift_share;
  const est::PumpDriftEstimator& pump = firmware->estimator().estimator().pump_drift();
  r.pump_gap = pump.gap();
  r.pump_gap_sigmas = pump.gap_sigmas();
  r.pump_eps_pq_sigma = pump_eps_pq_sigma(pump);
  r.pump_drift_usable = pump.usable();
  r.calibration = firmware->calibration_status();
  r.self_calibration = firmware->estimator().pickoff_self_calibration();
  r.self_calibration_applied = firmware->self_calibration();
  r.self_calibration_keep = firmware->pickoff_map_to_keep();
  r.final_calibration = firmware->calibration();
  r.pump_edge = gyro.status().pump_edge;
  r.firmware_estimates = firmware->estimates();
  r.can_bus_off_events = target.can().counters().bus_off_events;
  r.can_restarts = gyro.can_restarts();
  summarise_identification(r, job, *firmware);
  summarise_executive(r, gyro);
  r.sim_stages = target.stage_times();
  if (log) log->flush();
  analyse_run(r, job);
  return r;
}

}  // namespace hrg::sim_run
