// SPDX-License-Identifier: MIT
#include "sim_target/resonator.hpp"

#include <cmath>

#include "coefficients.hpp"
#include "matrix_exp.hpp"
#include "sim_target/averaged_model.hpp"

namespace hrg::sim {

namespace {

using Mat2 = Eigen::Matrix2d;
using Mat4 = Eigen::Matrix4d;

constexpr double kRateReexpandRadS = 0.05;
constexpr double kOmegaReexpandRadS = 1e-3;

// Upper-right block of expm([[A, P], [0, A]] h): the exact first-order change
// of expm(A h) per unit of the perturbation P.
Mat4 first_order(const Mat4& a, const Mat4& p, double h) {
  Eigen::Matrix<double, 8, 8> m = Eigen::Matrix<double, 8, 8>::Zero();
  m.block<4, 4>(0, 0) = a * h;
  m.block<4, 4>(4, 4) = a * h;
  m.block<4, 4>(0, 4) = p * h;
  return detail::expm(m).block<4, 4>(0, 4);
}

Mat4 lower_left(const Mat2& k) {
  Mat4 m = Mat4::Zero();
  m.block<2, 2>(2, 0) = k;
  return m;
}

Mat4 lower_right(const Mat2& k) {
  Mat4 m = Mat4::Zero();
  m.block<2, 2>(2, 2) = k;
  return m;
}

}  // namespace

Resonator::Resonator(const ResonatorParams& params, const ElectrodeParams& electrodes,
                     const Effects& effects)
    : params_(params),
      electrodes_(electrodes),
      effects_(effects),
      pickoff_effects_(any_pickoff_effect(effects)),
      temp_(Profile::constant(params.temp_ref_c)),
      f_ref_hz_(params.f_hz) {}

void Resonator::set_params(const ResonatorParams& p) {
  params_ = p;
  expanded_ = false;
  if (!f_ref_set_) {  // the reference follows the resonator unless set apart
    f_ref_hz_ = p.f_hz;
    dt_last_ = -1.0;
  }
}
void Resonator::set_electrodes(const ElectrodeParams& e) {
  electrodes_ = e;
  expanded_ = false;
}
void Resonator::set_effects(const Effects& fx) {
  effects_ = fx;
  pickoff_effects_ = any_pickoff_effect(fx);
  expanded_ = false;
}
void Resonator::set_rate_profile(Profile rate_rad_s) {
  rate_ = std::move(rate_rad_s);
  rate_at_.bind(&rate_);
}
void Resonator::set_temperature_profile(Profile temp_c) {
  temp_ = std::move(temp_c);
  temp_at_.bind(&temp_);
}
void Resonator::set_reference_hz(double f_hz) {
  f_ref_hz_ = f_hz;
  f_ref_set_ = true;
  dt_last_ = -1.0;  // recompute the <V^2> window at the next step
}

double Resonator::omega_rad_s() const {
  return detail::thermal_omega(params_, effects_, temperature_c());
}

void Resonator::set_state(double x_v, double y_v, double vx_v_per_s, double vy_v_per_s) {
  u_ << x_v, y_v, vx_v_per_s, vy_v_per_s;
}

void Resonator::set_envelopes(std::complex<double> x_env, std::complex<double> y_env) {
  const double w = omega_rad_s();
  const std::complex<double> carrier = std::polar(1.0, w * time_s());
  const std::complex<double> i_w{0.0, w};
  set_state((x_env * carrier).real(), (y_env * carrier).real(), (i_w * x_env * carrier).real(),
            (i_w * y_env * carrier).real());
}

void Resonator::set_standing_wave(double a_A_v, double theta_rad, double a_B_v, double phase_rad) {
  std::complex<double> x;
  std::complex<double> y;
  standing_wave(a_A_v, theta_rad, a_B_v, phase_rad, x, y);
  set_envelopes(x, y);
}

void Resonator::envelopes(std::complex<double>& x_env, std::complex<double>& y_env) const {
  const double w = omega_rad_s();
  x_env = {u_(0), -u_(2) / w};
  y_env = {u_(1), -u_(3) / w};
}

void Resonator::expand(double rate_rad_s, double omega_rad_s, double dt_s) {
  const detail::Coefficients c = detail::coefficients(params_, effects_, params_.temp_ref_c, 0.0);
  const double w = omega_rad_s;
  const double dw2 = 2.0 * w * params_.half_split_rad_s();
  Mat2 stiff;
  stiff << w * w + dw2 * c.c4w, dw2 * c.s4w, dw2 * c.s4w, w * w - dw2 * c.c4w;
  const double nu = params_.nu_per_s();  // thermal and amplitude scaling enter as perturbations
  Mat2 damp;
  damp << 2.0 * nu * (1.0 + c.dmu * c.c4mu), 2.0 * nu * c.dmu * c.s4mu, 2.0 * nu * c.dmu * c.s4mu,
      2.0 * nu * (1.0 - c.dmu * c.c4mu);
  Mat2 coriolis_per_rate;  // G / Omega = 2K [[0, -1], [1, 0]]
  coriolis_per_rate << 0.0, -2.0 * params_.angular_gain, 2.0 * params_.angular_gain, 0.0;

  // Work in balanced coordinates [x, y, x'/w, y'/w]: the raw system matrix has
  // entries from 1 to w^2 and its exponential would lose digits in the squarings.
  Mat4 a = Mat4::Zero();
  a.block<2, 2>(0, 2) = Mat2::Identity() * w;
  a.block<2, 2>(2, 0) = -stiff / w;
  a.block<2, 2>(2, 2) = -damp - rate_rad_s * coriolis_per_rate;
  Eigen::Vector4d to_raw;
  to_raw << 1.0, 1.0, w, w;
  const auto raw = [&to_raw](const Mat4& m) -> Mat4 {
    return to_raw.asDiagonal() * m * to_raw.cwiseInverse().asDiagonal();
  };

  phi_ = raw(detail::expm<Mat4>(a * dt_s));
  phi_half_ = raw(detail::expm<Mat4>(a * (0.5 * dt_s)));

  Eigen::Matrix<double, 6, 6> ab = Eigen::Matrix<double, 6, 6>::Zero();
  ab.block<4, 4>(0, 0) = a * dt_s;
  ab.block<2, 2>(2, 4) = Mat2::Identity() * (electrodes_.forcer_gain_per_s2 / w * dt_s);
  gamma_ = to_raw.asDiagonal() * detail::expm(ab).block<4, 2>(0, 4);

  const Mat4 p_rate = lower_right(-coriolis_per_rate);
  Eigen::Matrix<double, 12, 12> m = Eigen::Matrix<double, 12, 12>::Zero();
  for (int i = 0; i < 3; ++i)
    m.block<4, 4>(4 * i, 4 * i) = a * dt_s;
  m.block<4, 4>(0, 4) = p_rate * dt_s;
  m.block<4, 4>(4, 8) = p_rate * dt_s;
  const Eigen::Matrix<double, 12, 12> em = detail::expm(m);
  psi_rate1_ = raw(em.block<4, 4>(0, 4));
  psi_rate2_ = raw(em.block<4, 4>(0, 8));

  Mat2 gap;
  gap << 1.0 + 0.5 * electrodes_.eps_p, 0.5 * electrodes_.eps_q, 0.5 * electrodes_.eps_q,
      1.0 - 0.5 * electrodes_.eps_p;
  psi_gap_ = raw(first_order(a, lower_left(gap / w), dt_s));
  psi_iso_ = raw(first_order(a, lower_left(-Mat2::Identity() / w), dt_s));
  psi_damp_ = raw(first_order(a, lower_right(-damp), dt_s));

  rate_gap_.bottomRows<4>() = psi_gap_;
  rate_prop_valid_ = false;
  spring_k_ = effects_.electrostatic_spring.enabled
                  ? -8.0 * kPi * params_.omega_rad_s() * effects_.electrostatic_spring.hz_per_v2
                  : 0.0;
  rate_c_ = rate_rad_s;
  omega_c_ = omega_rad_s;
  dt_c_ = dt_s;
  expanded_ = true;
}

Resonator::PumpLag Resonator::pump_lag(double delay_samples, double step_rad) {
  PumpLag lag;
  lag.whole = static_cast<int>(std::floor(delay_samples));
  const double frac = delay_samples - lag.whole;
  // Between two samples of a sinusoid at step_rad per sample, v(t - (k +
  // f) h) = [sin((1 - f) wh) v_k + sin(f wh) v_k+1] / sin(wh), exact; the
  // straight line between them is low by up to 1 - cos(wh / 2): 0.16 % at
  // 4.2 kHz and 100 kHz (5.95 samples), 0 at 5 kHz (5 samples).
  const double s = std::sin(step_rad);
  lag.w_whole = std::abs(s) > 1e-9 ? std::sin((1.0 - frac) * step_rad) / s : 1.0 - frac;
  lag.w_next = std::abs(s) > 1e-9 ? std::sin(frac * step_rad) / s : frac;
  return lag;
}

double Resonator::pump_delayed(const PumpLag& lag) const {
  const auto at = [this](int back) {
    return pump_hist_[(hist_pos_ - back + kHistory * 4) % kHistory];
  };
  return lag.w_whole * at(lag.whole) + lag.w_next * at(lag.whole + 1);
}

void Resonator::readd_pump_squares() {
  // Re-added exactly once per ring turn: the running sum's rounding cannot drift.
  constexpr int kMask = kHistory - 1;
  pump_sq_sum_ = 0.0;
  for (int i = 0; i < dc_window_.length; ++i)
    pump_sq_sum_ += pump_sq_hist_[(hist_pos_ - i) & kMask];
  pump_sum_valid_ = true;
}

void Resonator::prepare_step(double rate_rad_s, double w, double dt_s) {
  if (!expanded_ || dt_s != dt_c_ || std::abs(rate_rad_s - rate_c_) > kRateReexpandRadS ||
      std::abs(w - omega_c_) > kOmegaReexpandRadS) {
    expand(rate_rad_s, w, dt_s);
  }
  if (dt_s != dt_last_) {
    dt_last_ = dt_s;
    dc_window_ = pump_dc_window(1.0 / (f_ref_hz_ * dt_s), kHistory - 1);
    quarter_lag_ = pump_lag(std::min(kHistory - 2.0, 1.0 / (4.0 * f_ref_hz_ * std::abs(dt_s))),
                            2.0 * kPi * f_ref_hz_ * std::abs(dt_s));
    pump_sum_valid_ = false;
  }
  // The propagator at this rate, Phi + dO Psi1 + dO^2 Psi2, is formed only
  // when the rate changes (every step of a ramp, once per hold).
  const double d_rate = rate_rad_s - rate_c_;
  if (!rate_prop_valid_ || d_rate != rate_prop_d_) {
    rate_gap_.topRows<4>() = phi_ + d_rate * psi_rate1_ + (d_rate * d_rate) * psi_rate2_;
    rate_prop_d_ = d_rate;
    rate_prop_valid_ = true;
  }
}

void Resonator::step(const Drive& drive, double dt_s) {
  if (dt_s != step_s_) {
    t0_s_ = time_s();
    steps_ = 0;
    step_s_ = dt_s;
  }
  if (rate_at_.profile() != &rate_) rate_at_.bind(&rate_);  // after a copy or a move
  if (temp_at_.profile() != &temp_) temp_at_.bind(&temp_);
  const bool next_step = steps_ != 0 && steps_ == cursor_steps_ + 1;
  cursor_steps_ = steps_;
  const double t_mid = time_s() + 0.5 * dt_s;
  const double rate = rate_at_.value(t_mid, next_step, dt_s);
  const double temp_c = temp_at_.value(t_mid, next_step, dt_s);
  const double w = detail::thermal_omega(params_, effects_, temp_c);
  prepare_step(rate, w, dt_s);

  // E = x^2 + y^2 + (x'^2 + y'^2)/w^2, needed only by the amplitude-dependent effects.
  const bool needs_energy =
      effects_.duffing_stiffness.enabled || effects_.nonlinear_damping.enabled;
  const double energy =
      needs_energy ? u_(0) * u_(0) + u_(1) * u_(1) + (u_(2) * u_(2) + u_(3) * u_(3)) / (w * w)
                   : 0.0;
  Vec4 next = propagate(drive, u_);

  double c_iso = w * w - omega_c_ * omega_c_;
  if (effects_.duffing_stiffness.enabled) {
    // r^2 at the step's midpoint; its 2w part is restored by 1/sinc(w h), the
    // attenuation a value held over the step gives it.
    const Vec4 mid = phi_half_ * u_;
    const double r2 = mid(0) * mid(0) + mid(1) * mid(1);
    const double wh = w * dt_s;
    const double sinc = std::sin(wh) / wh;
    c_iso += effects_.duffing_stiffness.kappa_per_s2_v2(params_.omega_rad_s()) *
             (0.5 * energy + (r2 - 0.5 * energy) / sinc);
  }
  if (c_iso != 0.0) next.noalias() += psi_iso_ * (c_iso * u_);

  const double c_damp = detail::damping_scale(params_, effects_, temp_c, energy) - 1.0;
  if (c_damp != 0.0) next.noalias() += psi_damp_ * (c_damp * u_);

  u_ = next;
  ++steps_;
}

bool Resonator::inputs_held(std::size_t n, double dt_s, double& rate_rad_s, double& temp_c) {
  if (n == 0 || dt_s != step_s_ || dt_s != dt_last_) return false;
  if (effects_.duffing_stiffness.enabled || effects_.nonlinear_damping.enabled) return false;
  if (rate_at_.profile() != &rate_) rate_at_.bind(&rate_);
  if (temp_at_.profile() != &temp_) temp_at_.bind(&temp_);
  // The step midpoints as step() computes them.
  const double t_first = t0_s_ + static_cast<double>(steps_) * step_s_ + 0.5 * dt_s;
  const double t_last = t0_s_ + static_cast<double>(steps_ + n - 1) * step_s_ + 0.5 * dt_s;
  return rate_at_.constant_over(t_first, t_last, rate_rad_s) &&
         temp_at_.constant_over(t_first, t_last, temp_c);
}

std::size_t Resonator::ramp_run(std::size_t n, double dt_s, double* d_rate) {
  if (!kPlainMatchesEigen || pickoff_effects_ || n == 0 || dt_s != step_s_ || dt_s != dt_last_)
    return 0;
  if (effects_.duffing_stiffness.enabled || effects_.nonlinear_damping.enabled) return 0;
  if (rate_.kind() == Profile::Kind::sine) return 0;
  if (rate_at_.profile() != &rate_) rate_at_.bind(&rate_);
  if (temp_at_.profile() != &temp_) temp_at_.bind(&temp_);
  // The step midpoints as step() computes them.
  const auto t_mid = [this, dt_s](std::size_t k) {
    return t0_s_ + static_cast<double>(steps_ + k) * step_s_ + 0.5 * dt_s;
  };
  double temp_c = 0.0;
  if (!temp_at_.constant_over(t_mid(0), t_mid(n - 1), temp_c)) return 0;
  const double piece_end_s = rate_at_.piece_end_s(t_mid(0));
  const HeldCoefficients c = prepare_held(rate_at_.value(t_mid(0), false, dt_s), temp_c, dt_s);
  if (c.iso != 0.0 || c.damp != 0.0) return 0;
  std::size_t k = 0;
  for (; k < n; ++k) {
    const double t = t_mid(k);
    if (!(t < piece_end_s)) break;
    const double rate = rate_at_.value(t, true, dt_s);
    if (std::abs(rate - rate_c_) > kRateReexpandRadS) break;
    d_rate[k] = rate - rate_c_;
  }
  return k;
}

Resonator::HeldCoefficients Resonator::prepare_held(double rate_rad_s, double temp_c, double dt_s) {
  const double w = detail::thermal_omega(params_, effects_, temp_c);
  prepare_step(rate_rad_s, w, dt_s);
  return {w * w - omega_c_ * omega_c_, detail::damping_scale(params_, effects_, temp_c, 0.0) - 1.0};
}

PickoffOutput Resonator::measured_with_effects() const {
  double x = u_(0);
  double y = u_(1);
  double vy = u_(3);
  if (effects_.pickoff_misalignment.enabled) {
    const double b2 = 2.0 * effects_.pickoff_misalignment.angle_deg * kDegToRad;
    y = u_(1) * std::cos(b2) + u_(0) * std::sin(b2);
    vy = u_(3) * std::cos(b2) + u_(2) * std::sin(b2);
  }
  if (effects_.pickoff_gain_mismatch.enabled) {
    y *= 1.0 + effects_.pickoff_gain_mismatch.gain;
    vy *= 1.0 + effects_.pickoff_gain_mismatch.gain;
  }
  if (effects_.pickoff_phase_mismatch.enabled) {
    // Y e^{-i phi}: for a narrow-band signal at w, y(t - phi/w) = y cos phi - (y'/w) sin phi.
    const double phi = effects_.pickoff_phase_mismatch.phase_deg * kDegToRad;
    y = y * std::cos(phi) - vy / omega_rad_s() * std::sin(phi);
  }
  if (effects_.drive_feedthrough.enabled) {
    // c V e^{i psi}: Re(Vc e^{i psi} e^{iwt}) = cos psi V(t) - sin psi V(t - T/4).
    // V is the pump voltage at this sampling instant t_k, as the catalogue
    // and the averaged model define it (a band-limited ADC sees the held
    // steps' fundamental, not the step's edge). The last held word (over
    // [t_k - h, t_k)) carries the phase of its middle, half a step before
    // t_k: psi is advanced by w h / 2 (9 deg at 5 kHz and 100 kHz).
    const auto& ft = effects_.drive_feedthrough;
    const double half_step_rad = dt_last_ > 0.0 ? kPi * f_ref_hz_ * dt_last_ : 0.0;
    const double v_now = pump_hist_[hist_pos_];
    const double v_lag = pump_delayed(quarter_lag_);
    const double px = ft.x_phase_deg * kDegToRad + half_step_rad;
    const double py = ft.y_phase_deg * kDegToRad + half_step_rad;
    x += ft.x_v_per_v * (std::cos(px) * v_now - std::sin(px) * v_lag);
    y += ft.y_v_per_v * (std::cos(py) * v_now - std::sin(py) * v_lag);
  }
  return {x, y};
}

}  // namespace hrg::sim
