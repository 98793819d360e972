// SPDX-License-Identifier: MIT
#include "sim_target/control.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "sim_target/averaged_model.hpp"

// The resonator-and-noise loop has an AVX2 form where GCC targets x86-64
// (chosen at run time by the CPU, see resonator_noise_wide()).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define HRG_SIM_WIDE 1
#else
#define HRG_SIM_WIDE 0
#endif

namespace hrg::sim {

using hal::Status;

SimTarget::SimTarget() : board_{adc_, dac_, excitation_, fault_input_, can_, clock_, temperature_} {
  configure(SimConfig{});
}

void SimTarget::configure(const SimConfig& c) {
  if (c.adc.sample_rate_hz == 0 || c.adc.block_frames == 0) {
    throw std::invalid_argument("adc: sample_rate_hz and block_frames must be positive");
  }
  config_ = SimConfig(c);  // move-assign: releases the previous profiles' storage
  resonator_ = Resonator(c.resonator, c.electrodes, c.effects);
  resonator_.set_rate_profile(c.rate_rad_s);
  resonator_.set_temperature_profile(c.temp_c);
  resonator_.set_standing_wave(c.initial.amplitude_v, c.initial.theta_rad, c.initial.quad_v);
  adc_q_ = AdcQuantizer(c.adc);
  dac_q_ = DacQuantizer(c.dac);
  noise_.reseed(c.seed);
  can_.configure(c.can);
  excitation_.value = false;
  fault_input_.value = false;
  sample_index_ = 0;
  std::vector<hal::q31_t>().swap(dac_queue_);
  dac_head_ = 0;
  std::vector<hal::q31_t>(hal::kDacChannels * c.dac.latency_samples, 0).swap(dac_latency_);
  latency_pos_ = 0;
  dac_written_ = false;
  adc_stuck_ = {};
  adc_saturated_ = {};
  adc_last_ = {};
  dac_dead_ = {};
  burst_rms_v_ = 0.0;
  burst_left_s_ = 0.0;
  pattern_angle_rad_ = c.initial.theta_rad;
  last_theta_rad_ = c.initial.theta_rad;
  input_angle_rad_ = 0.0;
  input_rate_.bind(&config_.rate_rad_s);
  last_pump_v_ = 0.0;
  counters_ = {};
  stage_times_ = {};
  temperature_.reset(c.seed);
}

void SimTarget::set_rate_profile(Profile rate_rad_s) {
  config_.rate_rad_s = rate_rad_s;
  input_rate_.bind(&config_.rate_rad_s);
  resonator_.set_rate_profile(std::move(rate_rad_s));
}
void SimTarget::set_temperature_profile(Profile temp_c) {
  config_.temp_c = temp_c;
  resonator_.set_temperature_profile(std::move(temp_c));
}
void SimTarget::set_params(const ResonatorParams& p) {
  config_.resonator = p;
  resonator_.set_params(p);
}
void SimTarget::set_electrodes(const ElectrodeParams& e) {
  config_.electrodes = e;
  resonator_.set_electrodes(e);
}
void SimTarget::set_effects(const Effects& fx) {
  config_.effects = fx;
  resonator_.set_effects(fx);
}

void SimTarget::set_adc_stuck(std::size_t channel, bool stuck) { adc_stuck_.at(channel) = stuck; }
void SimTarget::set_adc_saturated(std::size_t channel, bool saturated) {
  adc_saturated_.at(channel) = saturated;
}
void SimTarget::set_dac_dead(std::size_t channel, bool dead) { dac_dead_.at(channel) = dead; }
void SimTarget::noise_burst(double rms_v, double duration_s) {
  burst_rms_v_ = rms_v;
  burst_left_s_ = duration_s;
}

double SimTarget::time_s() const {
  return static_cast<double>(sample_index_) / config_.adc.sample_rate_hz;
}

uint64_t SimTarget::sample_time_ns(uint64_t index) const {
  // Exact when the rate divides 1e9 (100 kHz: 10 us); otherwise rounded.
  const uint64_t fs = config_.adc.sample_rate_hz;
  return index / fs * 1'000'000'000ull + (index % fs) * 1'000'000'000ull / fs;
}

namespace {
// std::remainder(d, pi/2) without the library call where it is d itself:
// |d| < pi/4 (half the divisor, exact) rounds the quotient to 0, and the
// remainder d - 0 is exact. A block turns the pattern by far less.
double quarter_turn_remainder(double d_rad) {
  constexpr double kQuarterTurn = kPi / 2;
  if (std::fabs(d_rad) < 0.5 * kQuarterTurn) return d_rad;
  return std::remainder(d_rad, kQuarterTurn);
}
}  // namespace

TrueState SimTarget::true_state() const {
  TrueState s;
  s.t_s = time_s();
  cplx x;
  cplx y;
  resonator_.envelopes(x, y);
  const WaveState w = wave_state(x, y);
  s.pattern_angle_rad = pattern_angle_rad_ + quarter_turn_remainder(w.theta_rad - last_theta_rad_);
  s.input_angle_rad = input_angle_rad_;
  s.energy_v2 = w.energy_v2;
  s.a_A_v = w.a_A_v;
  s.a_B_v = w.a_B_v;
  s.rate_rad_s = resonator_.rate_rad_s();
  s.temp_c = resonator_.temperature_c();
  s.excitation_enabled = excitation_.value;
  s.pump_v = last_pump_v_;
  return s;
}

void SimTarget::fill_drives(std::size_t m) {
  if (wide_) {
    fill_drives_wide(m);
  } else {
    fill_drives_loop(m);
  }
}

[[gnu::always_inline]] inline void SimTarget::fill_drives_loop(std::size_t m) {
  // Double buffer: the frames the firmware queued, then zeros when none is
  // waiting (an underrun once the firmware has written).
  constexpr std::size_t kCh = hal::kDacChannels;
  const std::size_t queued = std::min(dac_queue_.size() / kCh - dac_head_, m);
  if (queued < m && dac_written_) counters_.dac_underruns += m - queued;
  const hal::q31_t* input = dac_queue_.data() + kCh * dac_head_;
  const std::size_t latency = dac_latency_.size() / kCh;
  if (m < latency) {  // the latency line frame by frame
    if (queued > 0) std::copy_n(input, kCh * queued, words_.data());
    std::fill_n(words_.begin() + static_cast<std::ptrdiff_t>(kCh * queued), kCh * (m - queued), 0);
    delay_frames(m);
    counters_.dac_saturated += dac_q_.convert_block(words_.data(), drive_v_.data(), kCh * m);
  } else {
    // Converted where the frames are, in output order: the latency line's
    // frames (oldest first), then the first m - latency inputs; the last
    // `latency` inputs become the line. Every output code counts at the rails.
    counters_.dac_saturated += delayed_out(latency);
    const std::size_t direct = std::min(queued, m - latency);
    double* out = drive_v_.data() + kCh * latency;
    counters_.dac_saturated += dac_q_.convert_block(input, out, kCh * direct);
    std::fill(out + kCh * direct, drive_v_.data() + kCh * m, 0.0);  // 0 V: code 0, not a rail
    if (latency > 0) delay_in(input, queued, m, latency);
  }
  // A channel is gated off (0 V) while the excitation is off or it is dead.
  std::array<bool, kCh> live{};
  for (std::size_t ch = 0; ch < kCh; ++ch)
    live[ch] = excitation_.value && !dac_dead_[ch];
  const double* v = drive_v_.data();
  for (std::size_t k = 0; k < m; ++k, v += kCh)
    drives_[k] = Drive{live[0] ? v[0] : 0.0, live[1] ? v[1] : 0.0, live[2] ? v[2] : 0.0};
  dac_head_ += queued;
  if (kCh * dac_head_ == dac_queue_.size()) {
    dac_queue_.clear();
    dac_head_ = 0;
  }
}

uint32_t SimTarget::delayed_out(std::size_t latency) {
  if (latency == 0) return 0;
  // The line's frames from latency_pos_ (the oldest) to its end, then from its start.
  constexpr std::size_t kCh = hal::kDacChannels;
  const std::size_t older = latency - latency_pos_;
  const hal::q31_t* line = dac_latency_.data();
  double* out = drive_v_.data();
  return dac_q_.convert_block(line + kCh * latency_pos_, out, kCh * older) +
         dac_q_.convert_block(line, out + kCh * older, kCh * latency_pos_);
}

void SimTarget::delay_in(const hal::q31_t* input, std::size_t queued, std::size_t m,
                         std::size_t latency) {
  // The last `latency` of the m input frames (queued ones, then zeros) become the line.
  constexpr std::size_t kCh = hal::kDacChannels;
  const std::size_t first = m - latency;
  const std::size_t from_queue = queued > first ? queued - first : 0;
  std::copy_n(input + kCh * first, kCh * from_queue, dac_latency_.begin());
  std::fill(dac_latency_.begin() + static_cast<std::ptrdiff_t>(kCh * from_queue),
            dac_latency_.end(), 0);
  latency_pos_ = 0;
}

void SimTarget::delay_frames(std::size_t m) {
  // Frame k leaves the ring at pos and frame k's input takes its place.
  constexpr std::size_t kCh = hal::kDacChannels;
  const std::size_t latency = dac_latency_.size() / kCh;
  hal::q31_t* in = words_.data();
  std::size_t pos = latency_pos_;
  for (std::size_t k = 0; k < m; ++k) {
    std::swap_ranges(in + kCh * k, in + kCh * (k + 1), dac_latency_.data() + kCh * pos);
    pos = pos + 1 == latency ? 0 : pos + 1;
  }
  latency_pos_ = pos;
}

namespace {

// Host time of the block's stages, read only while profiling is on.
class StageLaps {
 public:
  explicit StageLaps(SimStageTimes* times) : times_(times) {
    if (times_) last_ = std::chrono::steady_clock::now();
  }
  void lap(uint64_t SimStageTimes::*stage) {
    if (!times_) return;
    const auto now = std::chrono::steady_clock::now();
    times_->*stage += static_cast<uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(now - last_).count());
    last_ = now;
  }

 private:
  SimStageTimes* times_;
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace

void SimTarget::run_resonator(std::size_t n, double dt) {
  if (wide_) {
    resonator_wide(n, dt);
  } else {
    resonator_loop<false>(n, dt);
  }
}

template <bool kWide>
[[gnu::always_inline]] inline void SimTarget::resonator_loop(std::size_t n, double dt) {
  const double offset_x = config_.adc.offset_v[0];
  const double offset_y = config_.adc.offset_v[1];
  double* volts = volts_.data();
  resonator_.step_block<kWide>(
      drives_.data(), n, dt,
      [ volts, offset_x, offset_y ](std::size_t k, const PickoffOutput& p)
          __attribute__((always_inline)) {
            volts[2 * k] = p.x_v + offset_x;
            volts[2 * k + 1] = p.y_v + offset_y;
          });
}

bool SimTarget::plain_noise() const {
  const auto& rms = config_.adc.noise_v_rms;
  return (rms[0] != 0.0 || rms[1] != 0.0) && !(burst_left_s_ > 0.0);
}

template <bool kWide>
[[gnu::always_inline]] inline void SimTarget::resonator_noise_loop(std::size_t n, double dt) {
  // run_resonator() and add_noise() in one loop, the same expressions and
  // draws in the same order: the normals are drawn while the step's
  // dependency chain runs.
  const double offset_x = config_.adc.offset_v[0];
  const double offset_y = config_.adc.offset_v[1];
  const double rms_x = config_.adc.noise_v_rms[0];
  const double rms_y = config_.adc.noise_v_rms[1];
  double* volts = volts_.data();
  detail::Gaussian::Stream noise(noise_);
  resonator_.step_block<kWide>(
      drives_.data(), n, dt,
      [ volts, offset_x, offset_y, rms_x, rms_y, &noise ](std::size_t k, const PickoffOutput& p)
          __attribute__((always_inline)) {
            const double nx = noise.normal();
            const double ny = noise.normal();
            volts[2 * k] = (p.x_v + offset_x) + rms_x * nx;
            volts[2 * k + 1] = (p.y_v + offset_y) + rms_y * ny;
          });
  noise.commit();
}

#if HRG_SIM_WIDE
// The same loop compiled for AVX2: the resonator's held-inputs step on four
// rows at a time (Resonator::step_wide()); everything else as compiled for
// the baseline, with the same bits (AVX2 brings no fused multiply-add).
[[gnu::target("avx2")]] void SimTarget::resonator_noise_wide(std::size_t n, double dt) {
  resonator_noise_loop<true>(n, dt);
}

// The resonator alone (noise added apart: bursts, profiling), as above.
[[gnu::target("avx2")]] void SimTarget::resonator_wide(std::size_t n, double dt) {
  resonator_loop<true>(n, dt);
}

// The DAC's conversions with the compiler's AVX2 vectors (integers to
// doubles and one product each: exact, so the same bits).
[[gnu::target("avx2")]] void SimTarget::fill_drives_wide(std::size_t m) { fill_drives_loop(m); }

// The ADC's conversions four at a time (AdcQuantizer::convert_lanes()).
[[gnu::target("avx2")]] uint32_t SimTarget::convert_wide(const double* v, hal::q31_t* out,
                                                         std::size_t n) const {
  return adc_q_.convert_lanes<4>(v, out, n);
}

bool SimTarget::cpu_has_wide() {
  __builtin_cpu_init();  // a SimTarget may be built before the constructors that run it
  return __builtin_cpu_supports("avx2") != 0;
}
#else
void SimTarget::resonator_wide(std::size_t n, double dt) { resonator_loop<false>(n, dt); }

void SimTarget::fill_drives_wide(std::size_t m) { fill_drives_loop(m); }

uint32_t SimTarget::convert_wide(const double* v, hal::q31_t* out, std::size_t n) const {
  return adc_q_.convert_block(v, out, n);
}

void SimTarget::resonator_noise_wide(std::size_t n, double dt) {
  resonator_noise_loop<false>(n, dt);
}

bool SimTarget::cpu_has_wide() { return false; }
#endif

void SimTarget::run_resonator_with_noise(std::size_t n, double dt) {
  if (wide_) {
    resonator_noise_wide(n, dt);
  } else {
    resonator_noise_loop<false>(n, dt);
  }
}

void SimTarget::add_noise(std::size_t n, double dt) {
  const auto& rms = config_.adc.noise_v_rms;
  if (rms[0] == 0.0 && rms[1] == 0.0 && !(burst_left_s_ > 0.0)) return;
  noise_.fill(noise_buf_.data(), 2 * n);
  if (!(burst_left_s_ > 0.0)) {
    for (std::size_t k = 0; k < n; ++k) {
      volts_[2 * k] += rms[0] * noise_buf_[2 * k];
      volts_[2 * k + 1] += rms[1] * noise_buf_[2 * k + 1];
    }
    return;
  }
  // hypot only while a burst is on (it may end within the chunk).
  std::array<double, 2> burst_rms = rms;
  if (burst_left_s_ > 0.0)
    burst_rms = {std::hypot(rms[0], burst_rms_v_), std::hypot(rms[1], burst_rms_v_)};
  for (std::size_t k = 0; k < n; ++k) {
    const bool burst = burst_left_s_ > 0.0;
    for (std::size_t ch = 0; ch < hal::kAdcChannels; ++ch)
      volts_[2 * k + ch] += (burst ? burst_rms[ch] : rms[ch]) * noise_buf_[2 * k + ch];
    if (burst) burst_left_s_ -= dt;
  }
}

uint32_t SimTarget::quantize(std::size_t n, hal::q31_t* out) {
  uint32_t clipped = 0;
  if (adc_stuck_[0] || adc_stuck_[1] || adc_saturated_[0] || adc_saturated_[1]) {
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t ch = 0; ch < hal::kAdcChannels; ++ch)
        clipped += quantize_sample(ch, volts_[2 * k + ch], out[2 * k + ch]);
    }
    return clipped;
  }
  clipped = wide_ ? convert_wide(volts_.data(), out, 2 * n)
                  : adc_q_.convert_block(volts_.data(), out, 2 * n);
  if (n > 0) adc_last_ = {out[2 * n - 2], out[2 * n - 1]};  // what a stuck channel holds
  return clipped;
}

Status SimTarget::produce_block(std::span<hal::q31_t> frames, uint64_t& t_first_ns,
                                uint32_t& clipped) {
  const uint32_t n = config_.adc.block_frames;
  if (frames.size() != static_cast<std::size_t>(n) * hal::kAdcChannels) {
    return Status::invalid_argument;
  }
  StageLaps laps(profiling_ ? &stage_times_ : nullptr);
  const double dt = 1.0 / config_.adc.sample_rate_hz;
  const double t0 = time_s();
  t_first_ns = sample_time_ns(sample_index_);
  clipped = 0;
  // In chunks of kChunk samples: the DAC's drives, then the resonator
  // (pickoffs at t_k, then one step under drive k), the pickoff noise and
  // the ADC, stage by stage: each stage is a tight loop over the chunk.
  for (std::size_t done = 0; done < n; done += kChunk) {
    const std::size_t m = std::min<std::size_t>(kChunk, n - done);
    fill_drives(m);
    last_pump_v_ = drives_[m - 1].pump_v;
    laps.lap(&SimStageTimes::dac_ns);
    if (plain_noise() && !profiling_) {
      run_resonator_with_noise(m, dt);
      laps.lap(&SimStageTimes::resonator_ns);
    } else {
      run_resonator(m, dt);
      laps.lap(&SimStageTimes::resonator_ns);
      add_noise(m, dt);
      laps.lap(&SimStageTimes::noise_ns);
    }
    sample_index_ += m;
    clipped += quantize(m, frames.data() + 2 * done);
    laps.lap(&SimStageTimes::adc_ns);
  }
  // Input angle: the exact integral of the rate profile over the block.
  const double t1 = time_s();
  input_angle_rad_ += input_rate_.integral(t0, t1);
  cplx x;
  cplx y;
  resonator_.envelopes(x, y);
  const double theta = wave_angle_rad(x, y);
  pattern_angle_rad_ += quarter_turn_remainder(theta - last_theta_rad_);
  last_theta_rad_ = theta;
  can_.tick(t1 - t0);
  counters_.adc_clipped += clipped;
  ++counters_.blocks;
  stage_times_.samples += n;
  laps.lap(&SimStageTimes::block_ns);
  return Status::ok;
}

hal::ConverterInfo SimTarget::SimAdc::info() const {
  const auto& c = t->config_.adc;
  return {c.sample_rate_hz, c.block_frames, c.full_scale_v};
}

Status SimTarget::SimAdc::read_block(std::span<hal::q31_t> frames, uint64_t& t_first_ns,
                                     uint32_t& clipped) {
  return t->produce_block(frames, t_first_ns, clipped);
}

hal::ConverterInfo SimTarget::SimDac::info() const {
  const auto& c = t->config_;
  return {c.adc.sample_rate_hz, c.adc.block_frames, c.dac.full_scale_v};
}

Status SimTarget::SimDac::write_block(std::span<const hal::q31_t> frames) {
  const std::size_t n = t->config_.adc.block_frames;
  if (frames.size() != n * hal::kDacChannels) return Status::invalid_argument;
  if (t->dac_queue_.size() / hal::kDacChannels - t->dac_head_ >= 4 * n)
    return Status::would_block;  // four blocks ahead at most
  t->dac_queue_.insert(t->dac_queue_.end(), frames.begin(), frames.end());  // one copy
  t->dac_written_ = true;
  return Status::ok;
}

void SimTarget::SimTemperature::reset(uint64_t seed) {
  // Its own stream: reading the sensor leaves the pickoff noise's bits alone.
  noise.reseed(seed ^ 0x7E3A5F0D1C2B4A69ull);
  lagged_c = t->resonator_.temperature_c();
  last_t_s = t->time_s();
}

Status SimTarget::SimTemperature::read(double& temp_c) {
  const TemperatureSensorConfig& c = t->config_.temperature_sensor;
  if (!c.present) return Status::closed;
  const double now_s = t->time_s();
  const double dt_s = now_s - last_t_s;
  last_t_s = now_s;
  // Exact first-order lag for a temperature held over the step.
  const double true_c = t->resonator_.temperature_c();
  lagged_c += (c.lag_s > 0.0 ? -std::expm1(-dt_s / c.lag_s) : 1.0) * (true_c - lagged_c);
  double v = lagged_c + c.noise_c_rms * noise.normal();
  if (c.lsb_c > 0.0) v = std::round(v / c.lsb_c) * c.lsb_c;
  temp_c = v;
  return Status::ok;
}

uint64_t SimTarget::SimClock::now_ns() const { return t->sample_time_ns(t->sample_index_); }

Status SimTarget::SimClock::sleep_until_ns(uint64_t t_ns) {
  return t_ns < now_ns() ? Status::timeout : Status::ok;
}

}  // namespace hrg::sim
