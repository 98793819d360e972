// SPDX-License-Identifier: MIT
#include "sim_tools/job.hpp"

#include <chrono>
#include <ctime>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "can/candump_log.hpp"
#include "firmware/dsp_chain_port.hpp"
#include "firmware/estimator_port.hpp"
#include "hal/linux/linux_clock.hpp"
#include "hal/linux/realtime.hpp"
#include "sim_target/control.hpp"
#include "sim_tools/console.hpp"

namespace hrg::simtools {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr double kRadSToDph = 180.0 / kPi * 3600.0;
// Runs at least this long get an identification phase of their own, until
// kLongIdentS of simulated time.
constexpr double kLongRunS = 1800.0;
constexpr double kLongIdentS = 800.0;

// Rate-table schedule, built as a piecewise-linear profile of the case rate.
struct Schedule {
  std::vector<sim::ProfilePoint> pts{{0.0, 0.0}};
  double t = 0.0;
  void hold(double dt) {
    t += dt;
    pts.push_back({t, pts.back().value});
  }
  // Turns the case by `angle_rad` at `rate_rad_s` with `ramp_s` ramps.
  void turn(double angle_rad, double rate_rad_s, double ramp_s) {
    const double r = std::copysign(rate_rad_s, angle_rad);
    const double cruise = std::fabs(angle_rad / r) - ramp_s;
    if (cruise < 0) throw std::invalid_argument("schedule: turn too short for its ramps");
    pts.push_back({t + ramp_s, r});
    pts.push_back({t + ramp_s + cruise, r});
    pts.push_back({t + 2 * ramp_s + cruise, 0.0});
    t += 2 * ramp_s + cruise;
  }
};

}  // namespace

std::array<double, 5> true_parameters(const sim::ResonatorParams& p) {
  const double nu = p.nu_per_s();
  const double dw = p.half_split_rad_s();
  return {nu, nu * p.dmu * std::cos(4 * p.th_mu_rad), nu * p.dmu * std::sin(4 * p.th_mu_rad),
          dw * std::cos(4 * p.th_w_rad), dw * std::sin(4 * p.th_w_rad)};
}

double true_drift_rad_s(const sim::ResonatorParams& p, double theta_rad, double q) {
  // physics.md section 3 (exact in q = a_B/a_A, as the averaged equations give).
  const double d_nu = p.nu_per_s() * p.dmu * std::sin(4 * (theta_rad - p.th_mu_rad));
  const double w = p.half_split_rad_s() * std::cos(4 * (theta_rad - p.th_w_rad));
  return (d_nu * (1 + q * q) - 2 * q * w) / (1 - q * q);
}

JobConfig default_job(double duration_s, int bias_angles) {
  JobConfig j;
  j.description =
      "seed resonator (5 kHz, Q 5e6, dQ/Q 0.1, split 5e-4 Hz); Earth rate at 55.75 deg N; "
      "ring-up from rest, rate-table sweep, IEEE 1431 style parked-angle bias test";
  sim::SimConfig& s = j.sim;
  s.resonator = sim::ResonatorParams{};  // the seed's example resonator
  // Axes away from the pickoffs so that all four anisotropy terms are non-zero.
  s.resonator.th_mu_rad = 15.0 * kDeg;
  s.resonator.th_w_rad = 40.0 * kDeg;
  // As sim_target/scenarios/default.toml: 1 uV/sqrt(Hz) pickoff noise over the
  // 50 kHz band, two samples of DAC pipeline, a resonator at rest (a residual
  // 1 mV ring).
  s.adc.noise_v_rms = {2.2e-4, 2.2e-4};
  s.dac.latency_samples = 2;
  s.initial.amplitude_v = 0.001;
  s.seed = 20240531;
  j.earth_rate_rad_s = sim::kEarthRateRadS * std::sin(j.latitude_deg * kDeg);

  // Ring-up from rest (forcers, then the pump) and lock take about 35 s; the
  // sweep starts after that. The pattern turns at -K/2 of the case rate.
  const double k = s.resonator.angular_gain;
  Schedule sch;
  sch.hold(45.0);
  const double sweep_rate = 10.0 * kDeg;  // case rate, pattern at about 2.8 deg/s
  // Two full 4 theta turns of the pattern: 180 deg of theta.
  const double sweep_case_rad = 2.0 * (kPi / 2.0) * 2.0 / k;
  sch.turn(sweep_case_rad, sweep_rate, 1.0);
  // Runs of an hour or more: the identification gets its own phase of
  // turning back and forth with long windows (see the window settings below)
  // before the parks, so that the model applied during the bias test has
  // converged (the decay-rate information of a window grows as T^3).
  const bool long_run = duration_s >= kLongRunS;
  if (long_run) {
    double sign = -1.0;
    while (sch.t < kLongIdentS) {
      sch.turn(sign * sweep_case_rad, sweep_rate, 1.0);
      sign = -sign;
    }
  }
  sch.hold(2.0);
  j.sweep_end_s = sch.t;

  // Bias test: steps of 90/n deg of pattern angle (a 4 theta turn over n parks).
  const double settle_s = 2.0;
  const double base_hold_s = 6.0;
  const double step_case_rad = (kPi / 2.0) / bias_angles * 2.0 / k;
  const double slew_rate = 20.0 * kDeg;
  const double step_s = std::fabs(step_case_rad) / slew_rate + 0.5;
  // After the parks the table stays still for a while: the longest still
  // record, for the Allan deviation (dropped first when the run is shortened).
  const double final_hold_s = 100.0;
  double hold_s = base_hold_s;
  const double t_bias0 = sch.t;
  const double parks_s = bias_angles * (step_s + settle_s + base_hold_s);
  if (duration_s > t_bias0 + parks_s + final_hold_s) {
    hold_s = (duration_s - final_hold_s - t_bias0) / bias_angles - step_s - settle_s;
  }
  for (int i = 0; i < bias_angles; ++i) {
    if (duration_s > 0 && sch.t + step_s + settle_s + hold_s > duration_s) break;
    sch.turn(-step_case_rad, slew_rate, 0.5);
    sch.hold(settle_s);
    const double t0 = sch.t;
    sch.hold(hold_s);
    j.parks.push_back({t0, sch.t});
  }
  if (duration_s <= 0) sch.hold(final_hold_s);
  j.duration_s = duration_s > 0 ? duration_s : sch.t;
  s.rate_rad_s = sim::Profile::ramps(sch.pts).add_offset(j.earth_rate_rad_s);

  fw::GyroConfig& g = j.gyro;
  g.angular_gain = k;
  g.amplitude_set_v = 1.0;
  // Long windows: the decay-rate information of one window grows as T^3
  // (slope of a noisy line), so one 1 s window is worth about 20 windows of
  // 130 ms for a quarter of the excitation-off time.
  g.windows.length_frames = 1000;
  g.windows.period_frames = 2000;
  g.windows.max_wait_frames = 10000;
  g.windows.bins = 16;
  g.windows.windows_per_bin = 4;
  g.windows.min_windows_per_bin = 2;
  g.windows.condition_good = 50.0;
  g.windows.coverage_good = 1.0;
  // The rate table turns the pattern here; commanded rotation is for a base
  // that never turns (the output is held while the pattern is moved).
  g.windows.rotate_on_static_base = false;
  if (long_run) {
    // 4 windows of 5 s per 4 theta bin while the table turns (64 windows,
    // 320 s: 8.9 % of an hour), 10 s apart so the AGC is back at the set
    // point between them; each carries 125 times the decay information of a
    // 1 s window. The campaign ends only when every bin has its 4.
    g.windows.length_frames = 5000;
    g.windows.period_frames = 10000;
    g.windows.max_wait_frames = 20000;
    g.windows.windows_per_bin = 4;
    g.windows.min_windows_per_bin = 4;
  }
  derive_firmware_config(j);
  return j;
}

JobConfig static_base_job(double duration_s) {
  JobConfig j = default_job(60.0, 4);
  j.description =
      "seed resonator on a static base (Earth rate at 55.75 deg N only); the firmware turns "
      "the pattern on purpose to fill the 4 theta bins";
  j.sim.rate_rad_s = sim::Profile::constant(j.earth_rate_rad_s);
  j.parks.clear();
  j.duration_s = duration_s > 0 ? duration_s : 300.0;
  j.sweep_end_s = j.duration_s;
  fw::WindowConfig& w = j.gyro.windows;
  w.rotate_on_static_base = true;
  w.min_windows_per_bin = 1;
  w.windows_per_bin = 2;
  w.period_frames = 1500;
  derive_firmware_config(j);
  return j;
}

void derive_firmware_config(JobConfig& j) {
  // The chain learns the converters from the simulated board's configuration
  // (ADC full scale 2.5 V there, 2.0 V in the chain's defaults).
  fw::ConverterInfo conv;
  conv.sample_rate_hz = j.sim.adc.sample_rate_hz;
  conv.block_frames = j.sim.adc.block_frames;
  conv.adc_full_scale_v = j.sim.adc.full_scale_v;
  conv.dac_full_scale_v = j.sim.dac.full_scale_v;
  conv.dac_latency_samples = j.sim.dac.latency_samples;
  j.chain = fw::chain_config_for(conv, j.chain);
  dsp::ChainConfig& c = j.chain;
  c.amplitude_setpoint_v = j.gyro.amplitude_set_v;
  j.estimator.angular_gain = j.gyro.angular_gain;
  // The pump's gap part of D_Phi is used only once the pattern angles seen
  // with the excitation on make its 3x3 fit well conditioned: an early fit
  // from a few nearby angles adds more than it removes (default run: ADB
  // 2.5 deg/h at the estimator's default 1e3, 0.15 deg/h at 10).
  j.estimator.pump.max_kappa_2 = 10.0;
  j.gyro.monitor.amplitude_set_v = j.gyro.amplitude_set_v;
}

namespace {

// The true state half-way between two instants (slow quantities, linear).
sim::TrueState midpoint(const sim::TrueState& a, const sim::TrueState& b) {
  sim::TrueState m = a;
  m.t_s = 0.5 * (a.t_s + b.t_s);
  m.pattern_angle_rad = 0.5 * (a.pattern_angle_rad + b.pattern_angle_rad);
  m.input_angle_rad = 0.5 * (a.input_angle_rad + b.input_angle_rad);
  m.energy_v2 = 0.5 * (a.energy_v2 + b.energy_v2);
  m.a_a_v = 0.5 * (a.a_a_v + b.a_a_v);
  m.a_b_v = 0.5 * (a.a_b_v + b.a_b_v);
  m.rate_rad_s = 0.5 * (a.rate_rad_s + b.rate_rad_s);
  m.temp_c = 0.5 * (a.temp_c + b.temp_c);
  return m;
}

void record_row(JobResult& r, const JobConfig& job, const fw::Gyro& g, const sim::TrueState& ts,
                double ref_offset_rad, bool drive_free, double true_angle0, double out0,
                double raw0) {
  const fw::GyroStatus& st = g.status();
  Row row{};
  // The row is the state at the centre of the demodulator's window, where
  // the envelope is (ts is taken there too).
  row.t_s = ts.t_s;
  // The chain demodulates against its NCO, whose phase the PLL moves every
  // block. The recording's cx..sy are against the fixed metadata reference
  // (ph = 2 pi f_ref t): x = Re((cx - i sx) e^(i ph_nco)) = Re((cx' - i sx')
  // e^(i ph)) with cx' - i sx' = (cx - i sx) e^(i (ph_nco - ph)).
  const double c = std::cos(ref_offset_rad);
  const double s = std::sin(ref_offset_rad);
  row.cx_v = st.chain.cx_v * c + st.chain.sx_v * s;
  row.sx_v = st.chain.sx_v * c - st.chain.cx_v * s;
  row.cy_v = st.chain.cy_v * c + st.chain.sy_v * s;
  row.sy_v = st.chain.sy_v * c - st.chain.cy_v * s;
  row.exc = drive_free ? 0 : 1;
  row.excitation_cmd = st.excitation_on ? 1 : 0;
  row.pump_v = st.chain.pump_v;
  row.temp_c = ts.temp_c;
  row.rate_dps = ts.rate_rad_s / kDeg;
  row.pll_hz = st.chain.f_ref_hz;
  row.quad_v = st.chain.a_b_v;
  row.mode = static_cast<int>(st.mode);
  row.theta_deg = st.theta_unwrapped_rad / kDeg;
  row.out_angle_deg = (st.out_angle_rad - out0) / kDeg;
  row.raw_angle_deg = (st.out_raw_angle_rad - raw0) / kDeg;
  row.true_angle_deg = (ts.input_angle_rad - true_angle0) / kDeg;
  row.true_theta_deg = ts.pattern_angle_rad / kDeg;
  row.a_a_v = st.chain.a_a_v;
  row.a_b_v = st.chain.a_b_v;
  row.drift_model_dph = st.drift_rad_s / job.gyro.angular_gain * kRadSToDph;
  row.drift_control_dph = st.control_drift_rad_s / job.gyro.angular_gain * kRadSToDph;
  const double q = ts.a_a_v > 0 ? ts.a_b_v / ts.a_a_v : 0.0;
  row.drift_true_dph = true_drift_rad_s(job.sim.resonator, ts.pattern_angle_rad, q) /
                       job.gyro.angular_gain * kRadSToDph;
  row.out_valid = st.out_valid ? 1 : 0;
  row.pattern_cmd = st.pattern_control ? 1 : 0;
  r.rows.push_back(row);
}

void summarise_executive(JobResult& r, const fw::Gyro& g) {
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

void analyse(JobResult& r, const JobConfig& job) {
  // Errors against the truth over the valid output, and the drift model's
  // prediction for the raw error: it falls behind the truth at D/K
  // (Omega K = -2 theta' + D).
  double sum2 = 0;
  std::size_t n = 0;
  const double dt_h = 1.0 / job.telemetry_hz / 3600.0;
  double model_deg = 0, bound_deg = 0, raw_err = 0, out_err = 0;
  double control_sum = 0;
  std::size_t control_n = 0;
  const Row* prev = nullptr;
  for (Row& row : r.rows) {
    if (row.out_valid && prev != nullptr && prev->out_valid) {
      const double d_true = row.true_angle_deg - prev->true_angle_deg;
      raw_err += row.raw_angle_deg - prev->raw_angle_deg - d_true;
      out_err += row.out_angle_deg - prev->out_angle_deg - d_true;
    }
    row.raw_error_deg = raw_err;
    row.out_error_deg = out_err;
    prev = &row;
    if (!row.out_valid) continue;
    if (row.t_s >= r.t_operate_s) {
      control_sum += row.drift_control_dph;
      ++control_n;
    }
    model_deg -= row.drift_true_dph * dt_h;
    bound_deg += std::fabs(row.drift_true_dph) * dt_h;
    if (row.t_s < r.t_operate_s) continue;
    sum2 += out_err * out_err;
    ++n;
    r.tracking_max_deg = std::max(r.tracking_max_deg, std::fabs(out_err));
  }
  r.tracking_rms_deg = n ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0;
  r.control_drift_mean_dph = control_n ? control_sum / static_cast<double>(control_n) : 0.0;
  r.model_error_end_deg = model_deg;
  r.drift_bound_deg = bound_deg;
  r.raw_error_end_deg = raw_err;
  r.comp_error_end_deg = out_err;

  // Parked bias: slope of the angle error over each park, in deg/h.
  std::vector<double> th, braw, bcomp, bmodel;
  for (const Park& p : job.parks) {
    std::vector<double> t, eraw, ecomp, theta;
    double model = 0;
    for (const Row& row : r.rows) {
      if (row.t_s < p.t_begin_s || row.t_s > p.t_end_s || !row.out_valid) continue;
      t.push_back(row.t_s);
      eraw.push_back(row.raw_angle_deg - row.true_angle_deg);
      ecomp.push_back(row.out_angle_deg - row.true_angle_deg);
      theta.push_back(row.theta_deg * kDeg);
      model += row.drift_true_dph;
    }
    if (t.size() < 10) continue;
    ParkResult pr;
    double ts = 0;
    for (double v : theta)
      ts += v;
    pr.theta_rad = ts / static_cast<double>(theta.size());
    pr.bias_raw_dph = slope(t, eraw) * 3600.0;
    pr.bias_comp_dph = slope(t, ecomp) * 3600.0;
    // The raw output error grows at -D/K (Omega K = -2 theta' + D).
    pr.bias_model_dph = -model / static_cast<double>(t.size());
    r.parks.push_back(pr);
    th.push_back(pr.theta_rad);
    braw.push_back(pr.bias_raw_dph);
    bcomp.push_back(pr.bias_comp_dph);
    bmodel.push_back(pr.bias_model_dph);
  }
  r.fit_raw = fit_bias_4theta(th, braw);
  r.fit_comp = fit_bias_4theta(th, bcomp);
  r.fit_model = fit_bias_4theta(th, bmodel);

  // Allan deviation of the compensated output rate (truth removed) over the
  // longest stretch with a valid output on a still table (no rate-table
  // motion, no commanded pattern move).
  const double earth_dps = job.earth_rate_rad_s * 180.0 / 3.14159265358979323846;
  std::size_t best_begin = 0, best_len = 0, begin = 0;
  for (std::size_t i = 0; i <= r.rows.size(); ++i) {
    const bool still = i < r.rows.size() && r.rows[i].out_valid && !r.rows[i].pattern_cmd &&
                       r.rows[i].t_s >= r.t_operate_s &&
                       std::fabs(r.rows[i].rate_dps - earth_dps) < 1e-6;
    if (still) continue;
    if (i - begin > best_len) {
      best_len = i - begin;
      best_begin = begin;
    }
    begin = i + 1;
  }
  std::vector<double> angle;
  for (std::size_t i = best_begin; i < best_begin + best_len; ++i) {
    angle.push_back(r.rows[i].out_error_deg * kDeg);
  }
  r.allan_span_s = static_cast<double>(best_len) / job.telemetry_hz;
  r.allan = allan_deviation(angle, 1.0 / job.telemetry_hz);
}

}  // namespace

JobResult run_job(const JobConfig& job, const RunOptions& opt) {
  JobResult r;
  const bool progress = opt.progress;
  const std::string& can_log = opt.can_log;
  fw::DspChainPort chain(job.chain);
  if (const char* err = chain.error())
    throw std::invalid_argument(std::string("signal chain configuration: ") + err);
  sim::SimTarget& target = sim::target();
  target.configure(job.sim);
  fw::EstimatorPort ident(job.estimator);
  // Lockstep: the board's simulated clock paces (it returns at once) and a
  // host clock times the tasks. Real time: CLOCK_MONOTONIC does both, with
  // the simulated converters behind it.
  HostClock host_timer;
  hal::linux_board::LinuxClock rt_clock;
  hal::Board& sim_board = hal::board();  // the simulated target, chosen at link time
  hal::Board rt_board{sim_board.adc,         sim_board.dac, sim_board.excitation_enable,
                      sim_board.fault_input, sim_board.can, rt_clock};
  r.real_time = opt.real_time;
  if (opt.real_time) {
    hal::linux_board::RealtimeRequest req;
    req.priority = opt.rt_priority;
    char buf[200];
    r.realtime_setup =
        hal::linux_board::describe(hal::linux_board::setup_realtime(req), buf, sizeof buf);
  }
  // The firmware objects are large (the chain holds its filters): on the heap
  // here, statically allocated on a board.
  auto gyro = opt.real_time ? std::make_unique<fw::Gyro>(rt_board, chain, ident, rt_clock,
                                                         fw::Pacing::real_time, job.gyro)
                            : std::make_unique<fw::Gyro>(sim_board, chain, ident, host_timer,
                                                         fw::Pacing::lockstep, job.gyro);
  if (!gyro->board_ok())
    throw std::invalid_argument(
        "the simulated board's converters do not "
        "match the firmware's block layout");
  std::unique_ptr<can::CandumpLogWriter> log;
  if (!can_log.empty()) log = std::make_unique<can::CandumpLogWriter>(can_log, "can0");

  const auto frames = static_cast<uint64_t>(std::llround(job.duration_s * fw::kBaseRateHz));
  const auto row_every =
      static_cast<uint64_t>(std::max(1.0, std::round(fw::kBaseRateHz / job.telemetry_hz)));
  r.rows.reserve(frames / row_every + 1);
  ProgressBar bar(static_cast<double>(frames), progress);
  double true0 = 0, out0 = 0, raw0 = 0;
  bool have_ref = false;
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  std::size_t next_fault = 0;
  fw::Mode last_mode = fw::Mode::power_up;
  // The demodulator's output describes the envelope at the centre of its
  // window, dsp::kDecimatorOrder / 2 blocks before the block end (within a
  // sample, dsp::decimator_group_delay_samples): half-way between the states
  // kCentre and kCentre + 1 blocks back.
  constexpr std::size_t kCentre = dsp::kDecimatorOrder / 2;
  constexpr std::size_t kHist = kCentre + 2;
  // NCO phase minus 2 pi f_ref t at the end of this block and the ones before.
  double ref_offset_hist[kHist] = {};
  // The true state at the same instants.
  sim::TrueState true_hist[kHist];
  // A row is free of any drive once the last driven DAC word (played
  // dac_lead_frames + the DAC's pipeline latency after its block) lies before
  // the N (L - 1) + 1 samples the demodulator averages: exc = 0 only from then on.
  const double block_frames = static_cast<double>(job.chain.block_frames);
  const auto drive_free_blocks =
      static_cast<uint64_t>(1.0 + std::ceil((job.chain.dac_lead_frames +
                                             static_cast<double>(job.sim.dac.latency_samples) +
                                             (dsp::kDecimatorOrder - 1.0) * (block_frames - 1.0)) /
                                            block_frames));
  uint64_t off_blocks = drive_free_blocks;  // blocks since the excitation was last on
  for (uint64_t k = 0; k < frames; ++k) {
    while (next_fault < job.faults.size() &&
           job.faults[next_fault].t_s <= static_cast<double>(k) / fw::kBaseRateHz) {
      const FaultEvent& e = job.faults[next_fault++];
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
    gyro->run_frame();
    const fw::GyroStatus& st = gyro->status();
    off_blocks = st.excitation_on ? 0 : off_blocks + 1;
    {
      // NCO phase at the first sample after this block (time t_s) against the
      // fixed reference 2 pi f_ref t.
      const double nco_cycles = static_cast<double>(chain.chain().nco_phase()) * 0x1p-32;
      const double ref_cycles = std::fmod(job.chain.f_center_hz * st.chain.t_s, 1.0);
      for (std::size_t i = kHist - 1; i > 0; --i) {
        ref_offset_hist[i] = ref_offset_hist[i - 1];
        true_hist[i] = true_hist[i - 1];
      }
      ref_offset_hist[0] = 2.0 * kPi * std::remainder(nco_cycles - ref_cycles, 1.0);
      true_hist[0] = target.true_state();
    }
    if (st.mode != last_mode) {
      ++r.mode_changes;
      if ((st.mode == fw::Mode::fault || st.mode == fw::Mode::safe) && r.t_first_fault_s < 0) {
        r.t_first_fault_s = st.chain.t_s;
      }
      if (st.mode == fw::Mode::operate && r.t_first_fault_s >= 0 && r.t_back_operate_s < 0) {
        r.t_back_operate_s = st.chain.t_s;
      }
      last_mode = st.mode;
    }
    r.faults_seen = static_cast<uint16_t>(r.faults_seen | st.faults);
    if (r.t_converged_s < 0 && gyro->scheduler().campaign_done()) r.t_converged_s = st.chain.t_s;
    if (st.mode == fw::Mode::operate && !r.reached_operate) {
      r.reached_operate = true;
      r.t_operate_s = st.chain.t_s;
    }
    if (r.t_can_back_s < 0 && !target.can().sent().empty() &&
        target.can().counters().bus_off_events > 0) {
      r.t_can_back_s = st.chain.t_s;
    }
    if (log) {
      auto& bus = target.can();
      for (const auto& f : bus.sent()) {
        log->write(f, static_cast<uint64_t>(st.chain.t_s * 1e9));
      }
      r.can_frames += bus.sent().size();
      bus.clear_sent();
    } else {
      r.can_frames += target.can().sent().size();
      target.can().clear_sent();
    }
    if (k % row_every != 0 || k + 1 < kHist) continue;  // rows from a full history on
    // The decimating filter's output is centred N (L - 1) / 2 samples before
    // the block's last sample, i.e. N / 2 blocks before t_s (N = 5): half-way
    // between the states kCentre and kCentre + 1 blocks back. Rate,
    // temperature and the true angles are written at that instant: stamped at
    // the block end instead, a rate ramp of 10 deg/s^2 puts a 0.015 deg/s
    // error into the input rate the envelope saw (sinc^3 figure), which the
    // audit takes for a pickoff gain mismatch.
    const sim::TrueState ts = midpoint(true_hist[kCentre], true_hist[kCentre + 1]);
    if (!have_ref && st.out_valid) {
      // Angles are compared from the first valid output on.
      true0 = ts.input_angle_rad;
      out0 = st.out_angle_rad;
      raw0 = st.out_raw_angle_rad;
      have_ref = true;
    }
    const double ref_offset_rad =
        ref_offset_hist[kCentre] +
        0.5 * std::remainder(ref_offset_hist[kCentre + 1] - ref_offset_hist[kCentre], 2.0 * kPi);
    record_row(r, job, *gyro, ts, ref_offset_rad, off_blocks >= drive_free_blocks, true0, out0,
               raw0);
    if (progress && k % 1000 == 0) {
      bar.update(static_cast<double>(k),
                 fmt("t=%.0f s %s", st.chain.t_s, fw::to_string(st.mode)).c_str());
    }
  }
  bar.finish();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  r.cpu_s = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  r.sim_s = job.duration_s;
  r.realtime_factor = r.wall_s > 0 ? r.sim_s / r.wall_s : 0.0;
  r.realtime_factor_cpu = r.cpu_s > 0 ? r.sim_s / r.cpu_s : 0.0;
  r.adc_wait_mean_us =
      frames ? static_cast<double>(gyro->status().adc_wait_ns) * 1e-3 / static_cast<double>(frames)
             : 0.0;
  r.sim_share =
      r.wall_s > 0 ? static_cast<double>(gyro->status().adc_wait_ns) * 1e-9 / r.wall_s : 0.0;
  r.final_mode = gyro->status().mode;
  r.can_bus_off_events = target.can().counters().bus_off_events;
  r.can_restarts = gyro->can_restarts();
  r.excitation_off_fraction = gyro->scheduler().excitation_off_fraction();
  r.windows = gyro->scheduler().windows();
  r.windows_accepted = ident.windows_accepted();
  r.campaign_done = gyro->scheduler().campaign_done();
  r.identification = ident.identification();
  r.truth = true_parameters(job.sim.resonator);
  r.condition = ident.health().condition;
  // Per-sample amplitude noise at the control rate: the pickoff noise (white,
  // sigma per ADC sample) mixed by 2 cos and low-passed to one sample per
  // block has the low-frequency density of a white sequence of variance
  // 2 sigma^2 / L at the block rate; a_A and a_B are unit-norm projections of
  // the x and y quadratures.
  const double adc_sigma_v =
      std::sqrt(0.5 * (job.sim.adc.noise_v_rms[0] * job.sim.adc.noise_v_rms[0] +
                       job.sim.adc.noise_v_rms[1] * job.sim.adc.noise_v_rms[1]));
  r.noise_sigma_v = adc_sigma_v * std::sqrt(2.0 / static_cast<double>(job.chain.block_frames));
  const est::ParamMatrix crb = ident.estimator().cramer_rao_bound(r.noise_sigma_v);
  for (int i = 0; i < est::kParams; ++i) {
    r.crb_sigma[static_cast<std::size_t>(i)] = crb(i, i) > 0.0 ? std::sqrt(crb(i, i)) : 0.0;
  }
  r.coverage = ident.health().coverage;
  summarise_executive(r, *gyro);
  if (log) log->flush();
  analyse(r, job);
  return r;
}

}  // namespace hrg::simtools
