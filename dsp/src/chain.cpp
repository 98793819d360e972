// SPDX-License-Identifier: MIT
#include "dsp/chain.hpp"

#include <cmath>
#include <numbers>
#include <cstddef>

namespace hrg::dsp {

namespace {
constexpr double kPi = std::numbers::pi;

double clamp_abs(double v, double lim) { return v > lim ? lim : (v < -lim ? -lim : v); }
double wrap_pi(double a) { return a - 2.0 * kPi * std::round(a / (2.0 * kPi)); }

// Appends text / a non-negative integer to a fixed buffer (no heap, no stdio
// on the target); truncates at the end.
class Message {
 public:
  Message& text(const char* t) {
    while (*t && n_ + 1 < sizeof(buf_))
      buf_[n_++] = *t++;
    buf_[n_] = 0;
    return *this;
  }
  Message& num(double v) {
    char d[24];
    int k = 0;
    auto u = static_cast<unsigned long long>(v < 0.0 ? 0.0 : (v > 1e18 ? 1e18 : v + 0.5));
    do {
      d[k++] = static_cast<char>('0' + u % 10);
      u /= 10;
    } while (u && k < 23);
    char t[24];
    for (int i = 0; i < k; ++i)
      t[i] = d[k - 1 - i];
    t[k] = 0;
    return text(t);
  }
  const char* str() const { return buf_; }

 private:
  char buf_[320] = {};
  std::size_t n_ = 0;
};

// The PLL range [f_min, f_max] must lie in the band where the decimator
// rejects the 2f image by >= 100 dB (decimator_band). Below it the block is
// too short; above it the sample rate is too low. The message names the
// frequency, the band and the change that serves it.
const char* check_resonance_band(const ChainConfig& c) {
  const DecimatorBand band = decimator_band(c.sample_rate_hz, c.block_frames);
  const bool low = c.f_min_hz < band.lo_hz;
  const bool high = c.f_max_hz > band.hi_hz;
  if (!low && !high) return nullptr;
  static Message m;
  m = Message{};
  m.text("chain config: ").text(low ? "f_min_hz " : "f_max_hz ").num(low ? c.f_min_hz : c.f_max_hz);
  m.text(" Hz is outside the resonance band ").num(band.lo_hz).text("..").num(band.hi_hz);
  m.text(" Hz that sample_rate_hz ").num(c.sample_rate_hz).text(" with block_frames ");
  m.num(c.block_frames).text(" serves (2f image >= 100 dB down); ");
  const double need = std::pow(10.0, kImageRejectionDb / (20.0 * kDecimatorOrder));
  if (band.lo_hz > band.hi_hz) {
    m.text("the block is too short for any resonance: raise block_frames to at least ");
    m.num(std::floor(need) + 1.0);
  } else if (low) {
    // |sin(pi 2 f_min / fs)| >= need / L: the shortest block that serves f_min.
    const double l_min = std::ceil(need / std::sin(2.0 * kPi * c.f_min_hz / c.sample_rate_hz));
    if (l_min <= kMaxBlockFrames) {
      m.text("raise block_frames to at least ").num(l_min).text(" (control rate ");
      m.num(c.sample_rate_hz / l_min).text(" Hz)");
    } else {
      m.text("even the longest block (2000 frames) does not serve it: lower sample_rate_hz");
    }
  } else {
    // 2 f_max <= (1 - a) fs with a from the block length.
    const double a = std::asin(need / c.block_frames) / kPi;
    m.text("sample rate too low: raise sample_rate_hz to at least ");
    m.num(std::ceil(2.0 * c.f_max_hz / (1.0 - a))).text(" with block_frames ").num(c.block_frames);
  }
  return m.str();
}
}  // namespace

double pump_phase_error_rad(double prev_pump_phase_rad, double wave_phase_rad) {
  return wrap_pi(kPi / 2.0 - 2.0 * (prev_pump_phase_rad - wave_phase_rad));
}

double quad_force_rate_v_s(double forcer_gain_per_s2, double w_rad_s, double u_q_v) {
  return forcer_gain_per_s2 / (2.0 * w_rad_s) * u_q_v;
}

const char* check_chain_config(const ChainConfig& c) {
  if (!(c.sample_rate_hz > 0.0)) return "chain config: sample_rate_hz must be > 0";
  if (c.block_frames < kMinBlockFrames || c.block_frames > kMaxBlockFrames)
    return "chain config: block_frames must be in [4, 2000]";
  if (!(c.adc_full_scale_v > 0.0)) return "chain config: adc_full_scale_v must be > 0";
  if (!(c.dac_full_scale_v > 0.0)) return "chain config: dac_full_scale_v must be > 0";
  if (!(c.dac_lead_frames >= 0.0 && c.dac_lead_frames < 1048576.0))
    return "chain config: dac_lead_frames must be in [0, 2^20)";
  if (!(c.f_min_hz > 0.0 && c.f_min_hz <= c.f_center_hz && c.f_center_hz <= c.f_max_hz))
    return "chain config: need 0 < f_min_hz <= f_center_hz <= f_max_hz";
  if (const char* band = check_resonance_band(c)) return band;
  if (!(c.q_factor > 0.0)) return "chain config: q_factor must be > 0";
  if (!(c.pump_gain_per_s2_v2 > 0.0)) return "chain config: pump_gain_per_s2_v2 must be > 0";
  if (!(c.forcer_gain_per_s2 > 0.0)) return "chain config: forcer_gain_per_s2 must be > 0";
  if (!(c.amplitude_setpoint_v > 0.0 && c.amplitude_setpoint_v < c.adc_full_scale_v))
    return "chain config: amplitude_setpoint_v must be in (0, adc_full_scale_v)";
  if (!(c.pump_max_v > 0.0 && c.pump_max_v <= c.dac_full_scale_v))
    return "chain config: pump_max_v must be in (0, dac_full_scale_v]";
  if (!(c.forcer_max_v > 0.0 && c.forcer_max_v <= c.dac_full_scale_v))
    return "chain config: forcer_max_v must be in (0, dac_full_scale_v]";
  if (!(c.pll_natural_hz > 0.0 && c.pll_damping > 0.0))
    return "chain config: pll_natural_hz and pll_damping must be > 0";
  if (!(c.agc_natural_rad_s > 0.0 && c.agc_damping > 0.0))
    return "chain config: agc_natural_rad_s and agc_damping must be > 0";
  if (!(c.quad_natural_rad_s > 0.0 && c.quad_damping > 0.0))
    return "chain config: quad_natural_rad_s and quad_damping must be > 0";
  if (!(c.min_amplitude_v > 0.0)) return "chain config: min_amplitude_v must be > 0";
  if (!(c.ring_up_enter >= 0.0 && c.ring_up_enter < c.ring_up_exit && c.ring_up_exit <= 1.0))
    return "chain config: need 0 <= ring_up_enter < ring_up_exit <= 1";
  if (!(c.lock_enter_rad > 0.0 && c.lock_enter_rad < c.lock_exit_rad))
    return "chain config: need 0 < lock_enter_rad < lock_exit_rad";
  return nullptr;
}

template <typename T>
Chain<T>::Chain(const ChainConfig& cfg)
    : cfg_(cfg), demod_(cfg.block_frames), pump_seen_(cfg.block_frames) {
  usable_ = check_chain_config(cfg) == nullptr;
  if (!usable_) return;
  const double w = 2.0 * kPi * cfg.f_center_hz;
  pll_.configure(Pll::Config{cfg.f_center_hz, cfg.f_min_hz, cfg.f_max_hz, cfg.pll_natural_hz,
                             cfg.pll_damping});
  lock_.configure(cfg.lock_enter_rad, cfg.lock_exit_rad, cfg.lock_blocks, 0.05);
  agc_.configure(Agc::Config{cfg.amplitude_setpoint_v, kPi * cfg.f_center_hz / cfg.q_factor,
                             cfg.agc_natural_rad_s, cfg.agc_damping, w, cfg.pump_gain_per_s2_v2,
                             cfg.pump_max_v});
  // a_B' = b u_q with b = g / 2w: PI on -a_B in volts of forcer.
  const double b = cfg.forcer_gain_per_s2 / (2.0 * w);
  const double wn = cfg.quad_natural_rad_s;
  quad_pi_.configure(2.0 * cfg.quad_damping * wn / b, wn * wn / b, -cfg.forcer_max_v,
                     cfg.forcer_max_v);
  reset();
}

template <typename T>
void Chain<T>::reset() {
  demod_.reset();
  pump_seen_.reset();
  pump_env_re_v_ = pump_env_im_v_ = 0.0;
  pll_.reset();
  lock_.reset();
  agc_.reset();
  quad_pi_.reset();
  unwrap_.reset();
  out_ = ChainOutputs{};
  phase_ = 0;
  step_ = phase_step_of_hz(cfg_.f_center_hz, cfg_.sample_rate_hz);
  pump_on_ = forcers_on_ = false;
  ring_up_ = true;
  have_pump_phase_ = false;
  wave_phase_rad_ = 0.0;
  c2_ = std::cos(2.0 * cfg_.ring_up_theta_rad);
  s2_ = std::sin(2.0 * cfg_.ring_up_theta_rad);
  u_a_v_ = u_q_v_ = u_r_v_ = v0_v_ = 0.0;
}

template <typename T>
void Chain<T>::set_pattern_command(bool enabled, double theta_target_rad, double max_rate_rad_s) {
  pattern_enabled_ = enabled;
  pattern_target_rad_ = theta_target_rad;
  pattern_max_rate_rad_s_ = std::fabs(max_rate_rad_s);
}

template <typename T>
bool Chain<T>::process(std::span<const q31_t> adc, std::span<q31_t> dac) {
  // A refused block breaks the pump phase history (the next error is 0).
  const bool had_pump_phase = have_pump_phase_;
  have_pump_phase_ = false;
  if (!usable_) return false;
  if (adc.size() != kChainAdcChannels * cfg_.block_frames ||
      dac.size() != kChainDacChannels * cfg_.block_frames)
    return false;

  const uint32_t phase_block_start = phase_;
  QuadSample<T> qs;
  demod_.process_block(adc, phase_, step_, qs);
  // The pump written after the previous ADC block acted during this one.
  double seen_re_v = 0.0;
  double seen_im_v = 0.0;
  pump_seen_.push(pump_env_re_v_, pump_env_im_v_, seen_re_v, seen_im_v);
  correction_.apply(seen_re_v, seen_im_v, qs);
  out_.pump_seen_v = std::hypot(seen_re_v, seen_im_v);

  const double fs_v = cfg_.adc_full_scale_v;
  const Quadratures<double> q{Ops::to_f64(qs.cx) * fs_v, Ops::to_f64(qs.sx) * fs_v,
                              Ops::to_f64(qs.cy) * fs_v, Ops::to_f64(qs.sy) * fs_v};
  const WaveVariables<double> w = wave_variables(q);
  out_.quad_v = q;
  out_.wave = w;
  out_.theta_A_rad = unwrap_.update(w.theta_A_rad);
  out_.phase_err_rad = w.phase_rad;

  const double dt_s = static_cast<double>(cfg_.block_frames) / cfg_.sample_rate_hz;
  const double prev_pump_phase_rad = out_.pump_phase_rad;
  update_loops(w, dt_s);
  update_drift_inputs(had_pump_phase, prev_pump_phase_rad);
  have_pump_phase_ = true;
  pump_env_re_v_ = v0_v_ * std::cos(out_.pump_phase_rad);
  pump_env_im_v_ = v0_v_ * std::sin(out_.pump_phase_rad);
  step_ = phase_step_of_hz(out_.pll_freq_hz, cfg_.sample_rate_hz);
  synthesize(phase_block_start, dac);
  ++out_.blocks;
  return true;
}

template <typename T>
void Chain<T>::update_loops(const WaveVariables<double>& w, double dt_s) {
  const bool valid = w.a_A_v > cfg_.min_amplitude_v;
  // Geometry of the drive: the pattern axis and the full wave phase (the
  // sign of the projection on the axis resolves the pi ambiguity of phase_rad).
  if (valid) {
    c2_ = std::cos(2.0 * w.theta_A_rad);
    s2_ = std::sin(2.0 * w.theta_A_rad);
    const double c_a = out_.quad_v.cx * c2_ + out_.quad_v.cy * s2_;
    const double s_a = out_.quad_v.sx * c2_ + out_.quad_v.sy * s2_;
    wave_phase_rad_ = std::atan2(-s_a, c_a);
  }
  out_.pll_freq_hz = pll_.update(w.phase_rad, valid, dt_s);
  out_.locked = lock_.update(w.phase_rad, valid);
  out_.excitation = pump_on_ || forcers_on_;

  const double a_set = agc_.setpoint_v();
  if (ring_up_ && w.a_A_v > cfg_.ring_up_exit * a_set) ring_up_ = false;
  if (!ring_up_ && w.a_A_v < cfg_.ring_up_enter * a_set) ring_up_ = true;
  // Pump: at its limit during ring-up (once there is a wave to pump), else
  // the AGC. Off: zero, AGC holds.
  v0_v_ = 0.0;
  if (pump_on_) {
    if (ring_up_) {
      v0_v_ = valid ? cfg_.pump_max_v : 0.0;
    } else {
      v0_v_ = agc_.update(w.a_A_v, dt_s);
    }
  }
  // Forcers: direct drive at resonance along the pattern during ring-up (the
  // pump alone cannot start a wave from zero amplitude), else quadrature
  // nulling and the optional pattern command. Off: zero, loops hold.
  u_a_v_ = u_q_v_ = u_r_v_ = 0.0;
  if (forcers_on_) {
    if (ring_up_) {
      u_a_v_ = cfg_.forcer_max_v;
    } else {
      u_q_v_ = quad_pi_.update(-w.a_B_v, dt_s);
    }
    if (pattern_enabled_ && valid) {
      const double w_rad_s = 2.0 * kPi * out_.pll_freq_hz;
      const double rate =
          clamp_abs(cfg_.pattern_gain_per_s * (pattern_target_rad_ - out_.theta_A_rad),
                    pattern_max_rate_rad_s_);
      u_r_v_ =
          clamp_abs(4.0 * w_rad_s * w.a_A_v * rate / cfg_.forcer_gain_per_s2, cfg_.forcer_max_v);
    }
  }
  out_.ring_up = ring_up_;
  out_.pump_v = v0_v_;
  out_.pump_phase_rad = wave_phase_rad_ + cfg_.pump_phase_rad;
  out_.quad_effort_v = u_q_v_;
  out_.pattern_effort_v = u_r_v_;
  out_.ring_up_drive_v = u_a_v_;
}

template <typename T>
void Chain<T>::update_drift_inputs(bool had_pump_phase, double prev_pump_phase_rad) {
  out_.quad_effort = cfg_.forcer_max_v > 0.0 ? u_q_v_ / cfg_.forcer_max_v : 0.0;
  // Only the pump's phase offset away from the ideal quarter turn counts.
  if (had_pump_phase && out_.pump_v > 0.0) {
    const double phi_a = out_.pump_phase_rad - cfg_.pump_phase_rad;  // this block's wave phase
    out_.pump_phase_error_rad = pump_phase_error_rad(prev_pump_phase_rad, phi_a);
  } else {
    out_.pump_phase_error_rad = 0.0;
  }
  const double f_hz = out_.pll_freq_hz > 0.0 ? out_.pll_freq_hz : cfg_.f_center_hz;
  out_.quad_force_sin_v_s = quad_force_rate_v_s(cfg_.forcer_gain_per_s2, 2.0 * kPi * f_hz, u_q_v_);
  out_.quad_force_cos_v_s = 0.0;
}

template <typename T>
void Chain<T>::synthesize(uint32_t phase_block_start, std::span<q31_t> dac) const {
  const std::size_t n = cfg_.block_frames;
  if (!pump_on_ && !forcers_on_) {
    for (std::size_t j = 0; j < kChainDacChannels * n; ++j)
      dac[j] = 0;
    return;
  }
  const double inv_fs = 1.0 / cfg_.dac_full_scale_v;
  auto coef = [inv_fs](double v) -> T {
    if constexpr (Ops::kFixed) {
      return q31_from_f64_sat(v * inv_fs);
    } else {
      return static_cast<T>(v * inv_fs);
    }
  };
  // Every channel is A cos psi + B sin psi: pump V0 cos(psi + phi) =
  // V0 cos phi cos psi - V0 sin phi sin psi, forcers as in chain.hpp. One
  // table lookup pair per frame serves all three.
  const T pc = coef(v0_v_ * std::cos(cfg_.pump_phase_rad));
  const T ps = coef(-v0_v_ * std::sin(cfg_.pump_phase_rad));
  const T fxc = coef(-u_q_v_ * s2_);
  const T fxs = coef(-u_a_v_ * c2_ + u_r_v_ * s2_);
  const T fyc = coef(u_q_v_ * c2_);
  const T fys = coef(-u_a_v_ * s2_ - u_r_v_ * c2_);
  // Phase advance over the DAC lead, modulo one turn (exact for leads of up
  // to 2^20 frames).
  const auto lead = static_cast<uint32_t>(
      static_cast<uint64_t>(static_cast<double>(step_) * cfg_.dac_lead_frames + 0.5));
  uint32_t psi = phase_block_start + lead + phase_of_rad(wave_phase_rad_);
  q31_t* d = dac.data();
  for (std::size_t j = 0; j < n; ++j) {
    const T c = cos_turns<T>(psi);
    const T s = sin_turns<T>(psi);
    d[3 * j] = Ops::mac2_to_q31(pc, c, ps, s);
    d[3 * j + 1] = Ops::mac2_to_q31(fxc, c, fxs, s);
    d[3 * j + 2] = Ops::mac2_to_q31(fyc, c, fys, s);
    psi += step_;
  }
}

template class Chain<q31_t>;
template class Chain<float>;
template class Chain<double>;

}  // namespace hrg::dsp
