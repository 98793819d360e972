// SPDX-License-Identifier: MIT
#include "sim_target/averaged_model.hpp"

#include <algorithm>
#include <cmath>

#include "coefficients.hpp"
#include "matrix_exp.hpp"

namespace hrg::sim {

namespace {

constexpr cplx kI{0.0, 1.0};

using C2 = Eigen::Matrix<cplx, 2, 2>;

// Real 2x2 block of z -> l z and of z -> n conj(z) on [Re z, Im z].
template <typename M>
void put_linear(M& a, int row, int col, cplx l) {
  a(row, col) += l.real();
  a(row, col + 1) -= l.imag();
  a(row + 1, col) += l.imag();
  a(row + 1, col + 1) += l.real();
}

template <typename M>
void put_conjugate(M& a, int row, int col, cplx n) {
  a(row, col) += n.real();
  a(row, col + 1) += n.imag();
  a(row + 1, col) += n.imag();
  a(row + 1, col + 1) -= n.real();
}

// R and S of the envelopes, and theta_A = atan2(S, R) / 4.
double r_of(double cx, double sx, double cy, double sy) {
  return cx * cx + sx * sx - cy * cy - sy * sy;
}
double s_of(double cx, double sx, double cy, double sy) { return 2.0 * (cx * cy + sx * sy); }
double theta_of(double s_v2, double r_v2) { return std::atan2(s_v2, r_v2) / 4.0; }
}  // namespace

WaveState wave_state(cplx x, cplx y) {
  WaveState w;
  const double cx = x.real();
  const double sx = -x.imag();
  const double cy = y.real();
  const double sy = -y.imag();
  w.energy_v2 = cx * cx + sx * sx + cy * cy + sy * sy;
  w.r_v2 = r_of(cx, sx, cy, sy);
  w.s_v2 = s_of(cx, sx, cy, sy);
  w.quad_v2 = 2.0 * (cx * sy - cy * sx);
  w.theta_rad = theta_of(w.s_v2, w.r_v2);
  const double plus = std::sqrt(std::max(0.0, w.energy_v2 + w.quad_v2));
  const double minus = std::sqrt(std::max(0.0, w.energy_v2 - w.quad_v2));
  w.a_A_v = 0.5 * (plus + minus);
  w.a_B_v = 0.5 * (plus - minus);
  const cplx along = x * std::cos(2.0 * w.theta_rad) + y * std::sin(2.0 * w.theta_rad);
  w.phase_a_rad = std::arg(along);
  return w;
}

double wave_angle_rad(cplx x, cplx y) {
  const double cx = x.real();
  const double sx = -x.imag();
  const double cy = y.real();
  const double sy = -y.imag();
  return theta_of(s_of(cx, sx, cy, sy), r_of(cx, sx, cy, sy));
}

void standing_wave(double a_A_v, double theta_rad, double a_B_v, double phase_rad, cplx& x_env,
                   cplx& y_env) {
  const double c = std::cos(2.0 * theta_rad);
  const double s = std::sin(2.0 * theta_rad);
  const cplx rot = std::polar(1.0, phase_rad);
  x_env = rot * (a_A_v * c + kI * a_B_v * s);
  y_env = rot * (a_A_v * s - kI * a_B_v * c);
}

void measure_envelopes(const Effects& fx, cplx x_env, cplx y_env, cplx pump_env_v, cplx& x_meas,
                       cplx& y_meas) {
  x_meas = x_env;
  y_meas = y_env;
  if (fx.pickoff_misalignment.enabled) {
    const double b2 = 2.0 * fx.pickoff_misalignment.angle_deg * kDegToRad;
    y_meas = y_env * std::cos(b2) + x_env * std::sin(b2);
  }
  if (fx.pickoff_gain_mismatch.enabled) y_meas *= 1.0 + fx.pickoff_gain_mismatch.gain;
  if (fx.pickoff_phase_mismatch.enabled) {
    y_meas *= std::polar(1.0, -fx.pickoff_phase_mismatch.phase_deg * kDegToRad);
  }
  if (fx.drive_feedthrough.enabled) {
    const auto& ft = fx.drive_feedthrough;
    x_meas += ft.x_v_per_v * pump_env_v * std::polar(1.0, ft.x_phase_deg * kDegToRad);
    y_meas += ft.y_v_per_v * pump_env_v * std::polar(1.0, ft.y_phase_deg * kDegToRad);
  }
}

AveragedModel::AveragedModel(const ResonatorParams& params, const ElectrodeParams& electrodes,
                             const Effects& effects, double f_ref_hz)
    : params_(params),
      electrodes_(electrodes),
      effects_(effects),
      f_ref_hz_(f_ref_hz > 0.0 ? f_ref_hz : params.f_hz),
      temp_(Profile::constant(params.temp_ref_c)) {
  r_(4) = 1.0;
}

void AveragedModel::set_params(const ResonatorParams& p) {
  params_ = p;
  dirty_ = true;
}
void AveragedModel::set_electrodes(const ElectrodeParams& e) {
  electrodes_ = e;
  dirty_ = true;
}
void AveragedModel::set_effects(const Effects& fx) {
  effects_ = fx;
  dirty_ = true;
}
void AveragedModel::set_rate_profile(Profile rate_rad_s) {
  rate_ = std::move(rate_rad_s);
  dirty_ = true;
}
void AveragedModel::set_temperature_profile(Profile temp_c) {
  temp_ = std::move(temp_c);
  dirty_ = true;
}
void AveragedModel::set_drive(const EnvelopeDrive& drive) {
  drive_ = drive;
  dirty_ = true;
}

void AveragedModel::set_standing_wave(double a_A_v, double theta_rad, double a_B_v,
                                      double phase_rad) {
  cplx x;
  cplx y;
  standing_wave(a_A_v, theta_rad, a_B_v, phase_rad, x, y);
  set_envelopes(x, y);
}

void AveragedModel::set_envelopes(cplx x_env, cplx y_env) {
  r_ << x_env.real(), x_env.imag(), y_env.real(), y_env.imag(), 1.0;
}

bool AveragedModel::state_dependent() const {
  if (effects_.duffing_stiffness.enabled || effects_.nonlinear_damping.enabled) return true;
  if (!drive_.excitation) return false;
  return (drive_.pump_follows_wave && drive_.pump_v != 0.0) ||
         (drive_.forcers_follow_wave && (drive_.forcer_x_v != 0.0 || drive_.forcer_y_v != 0.0));
}

cplx AveragedModel::pump_envelope_v() const {
  if (!drive_.excitation) return 0.0;
  double phase = drive_.pump_phase_rad;
  if (drive_.pump_follows_wave) phase += wave().phase_a_rad;
  return std::polar(drive_.pump_v, phase);
}

AveragedModel::Mat5 AveragedModel::system_matrix(double t_s, const Vec5& r) const {
  const cplx x{r(0), r(1)};
  const cplx y{r(2), r(3)};
  const double energy = std::norm(x) + std::norm(y);
  const double temp_c = temp_.value(t_s);
  const double rate = rate_.value(t_s);
  const detail::Coefficients c = detail::coefficients(params_, effects_, temp_c, energy);
  const double w = c.omega_rad_s;
  const double w_ref = 2.0 * kPi * f_ref_hz_;
  const cplx half_inv = kI / (2.0 * w);  // i / 2w

  cplx vc = 0.0;
  cplx fx = 0.0;
  cplx fy = 0.0;
  if (drive_.excitation) {
    const double phase_a = (drive_.pump_follows_wave || drive_.forcers_follow_wave)
                               ? wave_state(x, y).phase_a_rad
                               : 0.0;
    vc = std::polar(drive_.pump_v,
                    drive_.pump_phase_rad + (drive_.pump_follows_wave ? phase_a : 0.0));
    const cplx rot = drive_.forcers_follow_wave ? std::polar(1.0, phase_a) : cplx(1.0);
    fx = drive_.forcer_x_v * rot;
    fy = drive_.forcer_y_v * rot;
  }

  // Gap pattern G of the ring electrode.
  C2 gap;
  gap << 1.0 + 0.5 * electrodes_.eps_p, 0.5 * electrodes_.eps_q, 0.5 * electrodes_.eps_q,
      1.0 - 0.5 * electrodes_.eps_p;

  // Linear part L (acting on Z) and conjugate part N (acting on conj Z).
  C2 lin;
  lin << c.dw2 * c.c4w, c.dw2 * c.s4w, c.dw2 * c.s4w, -c.dw2 * c.c4w;
  lin = lin * half_inv;
  lin += (half_inv * (0.5 * c.kappa * energy)) * C2::Identity();
  lin -= (half_inv * (0.5 * c.spring_k * std::norm(vc))) * gap;
  const double nu = c.nu_per_s;
  // A frequency that drifts with temperature changes the amplitude adiabatically
  // (a^2 w is invariant): a'/a = -w'/(2w). The full-rate model has it by itself.
  double adiabatic = 0.0;
  if (effects_.thermal_frequency.enabled) {
    const double dw_dt =
        params_.omega_rad_s() * 1e-6 * effects_.thermal_frequency.ppm_per_c * temp_.derivative(t_s);
    adiabatic = -dw_dt / (2.0 * w);
  }
  // Both circular modes ring at sqrt(w^2 + (Omega K)^2) -+ Omega K: a common
  // second-order shift (Omega K)^2 / 2w that moves the phase, not the pattern.
  const double coriolis_shift = std::pow(rate * params_.angular_gain, 2) / (2.0 * w);
  const cplx detune = kI * (w - w_ref + coriolis_shift);
  lin(0, 0) += detune - nu * (1.0 + c.dmu * c.c4mu) + adiabatic;
  lin(1, 1) += detune - nu * (1.0 - c.dmu * c.c4mu) + adiabatic;
  lin(0, 1) += -nu * c.dmu * c.s4mu + rate * params_.angular_gain;
  lin(1, 0) += -nu * c.dmu * c.s4mu - rate * params_.angular_gain;

  C2 conj_part = (half_inv * (0.25 * c.kappa * (x * x + y * y))) * C2::Identity();
  conj_part -= (half_inv * (0.25 * electrodes_.pump_gain_per_s2_v2 * vc * vc)) * gap;

  const cplx force_scale = -half_inv * electrodes_.forcer_gain_per_s2;  // 1 / (2 i w) * g

  Mat5 a = Mat5::Zero();
  for (int j = 0; j < 2; ++j) {
    for (int k = 0; k < 2; ++k) {
      put_linear(a, 2 * j, 2 * k, lin(j, k));
      put_conjugate(a, 2 * j, 2 * k, conj_part(j, k));
    }
  }
  const cplx bx = force_scale * fx;
  const cplx by = force_scale * fy;
  a(0, 4) = bx.real();
  a(1, 4) = bx.imag();
  a(2, 4) = by.real();
  a(3, 4) = by.imag();
  return a;
}

void AveragedModel::step(double h, bool state_dep, bool inputs_vary) {
  if (state_dep) {
    const Mat5 a0 = system_matrix(t_s_, r_);
    const Vec5 r_mid = detail::expm<Mat5>(a0 * (0.5 * h)) * r_;
    const Mat5 a_mid = system_matrix(t_s_ + 0.5 * h, r_mid);
    r_ = detail::expm<Mat5>(a_mid * h) * r_;
  } else if (!inputs_vary && !dirty_ && h == cached_h_ && rate_.is_constant() &&
             temp_.is_constant()) {
    r_ = cached_phi_ * r_;  // constant system, same step: the cached propagator is exact
  } else {
    const Mat5 ah = system_matrix(t_s_ + 0.5 * h, r_) * h;
    if (ah != cached_ah_) {
      cached_ah_ = ah;
      cached_phi_ = detail::expm<Mat5>(ah);
    }
    cached_h_ = h;
    dirty_ = false;
    r_ = cached_phi_ * r_;
  }
  r_(4) = 1.0;
}

void AveragedModel::advance(double dt_s) {
  if (!(dt_s > 0.0)) return;
  const double t_end = t_s_ + dt_s;
  const bool state_dep = state_dependent();
  // Segments end at the profiles' corners (rate steps, ramp knees), so a step
  // never straddles a jump; within a segment, inputs that still vary (ramps,
  // sines) or amplitude-dependent terms take midpoint steps of at most max_step_s.
  while (t_s_ < t_end) {
    double seg_end =
        std::min({t_end, rate_.next_breakpoint_s(t_s_), temp_.next_breakpoint_s(t_s_)});
    if (!(seg_end > t_s_)) seg_end = t_end;
    const bool vary = rate_.varies_between(t_s_, seg_end) || temp_.varies_between(t_s_, seg_end);
    const double span = seg_end - t_s_;
    const int steps =
        (state_dep || vary) ? std::max(1, static_cast<int>(std::ceil(span / max_step_s_))) : 1;
    const double h = span / steps;
    for (int i = 0; i < steps; ++i) {
      step(h, state_dep, vary);
      t_s_ += h;
    }
    t_s_ = seg_end;
  }
}

Demodulated AveragedModel::demodulated() const { return demodulated(f_ref_hz_); }

Demodulated AveragedModel::demodulated(double f_ref_hz) const {
  cplx xm;
  cplx ym;
  measure_envelopes(effects_, x_envelope(), y_envelope(), pump_envelope_v(), xm, ym);
  if (f_ref_hz != f_ref_hz_) {
    const cplx rot = std::polar(1.0, 2.0 * kPi * (f_ref_hz_ - f_ref_hz) * t_s_);
    xm *= rot;
    ym *= rot;
  }
  return {xm.real(), -xm.imag(), ym.real(), -ym.imag()};
}

RecordingRow AveragedModel::row(double f_ref_hz) const {
  RecordingRow row;
  row.t_s = t_s_;
  row.d = demodulated(f_ref_hz);
  row.exc = drive_.excitation ? 1 : 0;
  row.pump_v = drive_.excitation ? drive_.pump_v : 0.0;
  row.temp_c = temperature_c();
  row.rate_dps = rate_rad_s() / kDegToRad;
  return row;
}

}  // namespace hrg::sim
