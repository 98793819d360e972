// SPDX-License-Identifier: MIT
#pragma once

// Control-rate loop elements of the chain: a PI controller with output limits
// and anti-windup, the PLL on the standing wave's phase, its lock detector
// with hysteresis and the amplitude loop (AGC) through the parametric pump.
// All in double at the control rate (1 kHz by default): the Cortex-M7 has a
// double-precision FPU and the cost per call is a few tens of operations.
// Task context, once per block; no allocation.

#include <cmath>
#include <numbers>
#include <cstdint>

namespace hrg::dsp {

// u = clamp(kp e + i), i += ki e dt, with conditional integration: the
// integrator does not move further into a limit the output already sits on
// (anti-windup), and it is itself kept inside the limits.
class PiController {
 public:
  void configure(double kp, double ki, double out_min, double out_max) {
    kp_ = kp;
    ki_ = ki;
    min_ = out_min;
    max_ = out_max;
  }
  void reset(double integrator = 0.0) { i_ = clamp(integrator); }

  // e: error (any unit), dt_s: control period. Returns the limited output.
  double update(double e, double dt_s) {
    const double u_free = kp_ * e + i_;
    const double di = ki_ * e * dt_s;
    const bool push_up = di > 0.0 && u_free >= max_;
    const bool push_down = di < 0.0 && u_free <= min_;
    if (!push_up && !push_down) i_ = clamp(i_ + di);
    u_ = clamp(kp_ * e + i_);
    return u_;
  }
  double output() const { return u_; }
  double integrator() const { return i_; }
  bool saturated() const { return u_ >= max_ || u_ <= min_; }

 private:
  double clamp(double v) const { return v < min_ ? min_ : (v > max_ ? max_ : v); }
  double kp_ = 0.0;
  double ki_ = 0.0;
  double min_ = 0.0;
  double max_ = 0.0;
  double i_ = 0.0;
  double u_ = 0.0;
};

// Lock detector with hysteresis: the phase error is smoothed by a one-pole
// filter; lock is declared after `enter_blocks` consecutive blocks below
// `enter_rad` and dropped as soon as it exceeds `exit_rad` (> enter_rad) or
// the amplitude is too small to measure a phase.
class LockDetector {
 public:
  void configure(double enter_rad, double exit_rad, uint32_t enter_blocks, double smooth) {
    enter_rad_ = enter_rad;
    exit_rad_ = exit_rad;
    enter_blocks_ = enter_blocks;
    smooth_ = smooth;
  }
  void reset() {
    locked_ = false;
    count_ = 0;
    level_rad_ = exit_rad_;
  }
  bool update(double phase_err_rad, bool valid) {
    if (!valid) {
      reset();
      return locked_;
    }
    level_rad_ += smooth_ * (std::fabs(phase_err_rad) - level_rad_);
    if (locked_) {
      if (level_rad_ > exit_rad_) {
        locked_ = false;
        count_ = 0;
      }
    } else if (level_rad_ < enter_rad_) {
      if (++count_ >= enter_blocks_) locked_ = true;
    } else {
      count_ = 0;
    }
    return locked_;
  }
  bool locked() const { return locked_; }
  double level_rad() const { return level_rad_; }

 private:
  double enter_rad_ = 0.02;
  double exit_rad_ = 0.1;
  uint32_t enter_blocks_ = 100;
  double smooth_ = 0.05;
  bool locked_ = false;
  uint32_t count_ = 0;
  double level_rad_ = 0.1;
};

// Second-order (type-2) PLL: the phase error phi of the standing wave against
// the NCO drives w_nco = w_center + kp phi + integral(ki phi). With the plant
// phi' = w_res - w_nco the closed loop is s^2 + kp s + ki: kp = 2 zeta wn,
// ki = wn^2. A frequency ramp r (rad/s^2) leaves a phase error r / wn^2.
// Limits: the output frequency stays in [f_min, f_max]; the integrator does
// not wind up against them.
class Pll {
 public:
  struct Config {
    double f_center_hz = 5000.0;
    double f_min_hz = 4990.0;
    double f_max_hz = 5010.0;
    double natural_hz = 12.0;  // wn / 2 pi
    double damping = 0.9;      // zeta
  };

  void configure(const Config& c) {
    cfg_ = c;
    const double wn = 2.0 * std::numbers::pi * c.natural_hz;
    const double w_c = 2.0 * std::numbers::pi * c.f_center_hz;
    const double w_min = 2.0 * std::numbers::pi * c.f_min_hz;
    const double w_max = 2.0 * std::numbers::pi * c.f_max_hz;
    pi_.configure(2.0 * c.damping * wn, wn * wn, w_min - w_c, w_max - w_c);
    reset();
  }
  void reset() {
    pi_.reset(0.0);
    f_hz_ = cfg_.f_center_hz;
  }

  // phase_err_rad: wave phase against the NCO (> 0: wave leads, resonance
  // above the NCO). valid = false holds the present frequency (no signal).
  // Returns the NCO frequency for the next block, Hz.
  double update(double phase_err_rad, bool valid, double dt_s) {
    if (valid) {
      const double dw = pi_.update(phase_err_rad, dt_s);
      f_hz_ = cfg_.f_center_hz + dw / (2.0 * std::numbers::pi);
    }
    return f_hz_;
  }
  double frequency_hz() const { return f_hz_; }
  bool at_limit() const { return pi_.saturated(); }

 private:
  Config cfg_{};
  PiController pi_;
  double f_hz_ = 5000.0;
};

// Amplitude loop through the parametric pump. The pump V = V0 cos(w t + phi_V)
// with phi_V = (wave phase) + pi/4 gives wave A the growth rate
// g = k_pump V0^2 / (8 w) (dsp/chain.hpp, seed section 6), so
// a_A' / a_A = g - nu: with the relative error e = (a_set - a_A) / a_set the
// plant is an integrator and g = nu + PI(e) closes a second-order loop
// s^2 + kp s + ki. g is limited to [0, g_max] (V0 up to the DAC limit) with
// anti-windup; V0 = sqrt(8 w g / k_pump).
class Agc {
 public:
  struct Config {
    double setpoint_v = 1.0;       // a_A set point, volts of pickoff
    double nu_per_s = 3.14159e-3;  // nominal damping (feed-forward), 1/s
    double natural_rad_s = 8.0;    // loop natural frequency
    double damping = 1.0;
    double omega_rad_s = 2.0 * std::numbers::pi * 5000.0;
    double pump_gain_per_s2_v2 = 87.73;  // k_pump
    double pump_max_v = 10.0;            // V0 limit
  };

  void configure(const Config& c) {
    cfg_ = c;
    const double g_max = growth_of_v0(c.pump_max_v);
    pi_.configure(2.0 * c.damping * c.natural_rad_s, c.natural_rad_s * c.natural_rad_s, 0.0, g_max);
    reset();
  }
  void reset() {
    pi_.reset(cfg_.nu_per_s);
    v0_ = 0.0;
  }
  void set_setpoint_v(double a_set_v) { cfg_.setpoint_v = a_set_v; }
  double setpoint_v() const { return cfg_.setpoint_v; }

  // a_A_v: measured amplitude. Returns V0 (volts) for the next block.
  double update(double a_A_v, double dt_s) {
    const double e = (cfg_.setpoint_v - a_A_v) / cfg_.setpoint_v;
    const double g = pi_.update(e, dt_s);
    v0_ = v0_of_growth(g);
    return v0_;
  }
  double pump_v() const { return v0_; }
  double growth_per_s() const { return pi_.output(); }
  bool saturated() const { return pi_.saturated(); }

  double growth_of_v0(double v0) const {
    return cfg_.pump_gain_per_s2_v2 * v0 * v0 / (8.0 * cfg_.omega_rad_s);
  }
  double v0_of_growth(double g) const {
    return g > 0.0 ? std::sqrt(8.0 * cfg_.omega_rad_s * g / cfg_.pump_gain_per_s2_v2) : 0.0;
  }

 private:
  Config cfg_{};
  PiController pi_;
  double v0_ = 0.0;
};

}  // namespace hrg::dsp
