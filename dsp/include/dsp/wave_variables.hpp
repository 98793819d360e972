// SPDX-License-Identifier: MIT
#pragma once

// Wave variables of the n = 2 standing wave from the demodulated quadratures
// (docs/physics.md section 2, the paper's eqs. 12-13, 17).
//
// Convention. The pickoffs are x (C, 0 deg) and y (D, 45 deg physical); the
// demodulator's reference is the NCO phase wt, and
//     x = cx cos wt + sx sin wt,   y = cy cos wt + sy sin wt,
// i.e. X = cx - i sx, Y = cy - i sy with x = Re(X e^{iwt}). A pattern made of
// wave A (amplitude a_A, antinode at physical angle theta_A, temporal phase
// phi relative to the reference) and wave B (a_B, in quadrature in time and
// at theta_A + 45 deg in space) gives
//     x = a_A cos2th cos(wt+phi) - a_B sin2th sin(wt+phi)
//     y = a_A sin2th cos(wt+phi) + a_B cos2th sin(wt+phi)
// so that
//     E = cx^2 + sx^2 + cy^2 + sy^2 = a_A^2 + a_B^2
//     R = cx^2 + sx^2 - cy^2 - sy^2 = (a_A^2 - a_B^2) cos 4theta_A
//     S = 2 (cx cy + sx sy)         = (a_A^2 - a_B^2) sin 4theta_A
//     Q = 2 (cx sy - cy sx)         = 2 a_A a_B
//     L = cx^2 + cy^2 - sx^2 - sy^2 = (a_A^2 - a_B^2) cos 2phi
//     P = 2 (cx sx + cy sy)         = -(a_A^2 - a_B^2) sin 2phi
// with E^2 = R^2 + S^2 + Q^2 identically. theta_A = atan2(S, R) / 4 and the
// phase error phi = atan2(-P, L) / 2 do not depend on each other, so the
// phase detector works at any pattern angle. phi > 0 means the wave leads the
// reference (the resonance is above the NCO frequency while phi grows).
//
// Everything here is for the slow (control-rate) path, in float or double;
// no heap, no exceptions, callable from any context.

#include <cmath>
#include <complex>
#include <cstdint>
#include <numbers>
#include <type_traits>

namespace hrg::dsp {

// Demodulated quadratures of both pickoffs, in pickoff units (the ADC's full
// scale when they come from the chain).
template <typename T>
struct Quadratures {
  static_assert(std::is_floating_point_v<T>, "wave variables are float or double");
  T cx{0};
  T sx{0};
  T cy{0};
  T sy{0};
};

template <typename T>
struct WaveVariables {
  static_assert(std::is_floating_point_v<T>, "wave variables are float or double");
  T E_v2{0};         // a_A^2 + a_B^2 (pickoff units squared)
  T Q_v2{0};         // 2 a_A a_B (quadrature)
  T R_v2{0};         // (a_A^2 - a_B^2) cos 4theta_A
  T S_v2{0};         // (a_A^2 - a_B^2) sin 4theta_A
  T a_A_v{0};        // working wave amplitude, >= 0
  T a_B_v{0};        // quadrature wave amplitude, signed like Q
  T theta_A_rad{0};  // pattern angle (physical), wrapped to (-pi/4, pi/4]
  T phase_rad{0};    // phase error phi of wave A against the reference, (-pi/2, pi/2]
};

// Computes all wave variables from one set of quadratures.
// Units: same as the quadratures (amplitudes) and radians. For E == 0 the
// angles and amplitudes are 0. Never overflows for |c|,|s| < 1e18 (double) or
// 1e9 (float).
template <typename T>
WaveVariables<T> wave_variables(const Quadratures<T>& q) {
  WaveVariables<T> w;
  const T xx = q.cx * q.cx + q.sx * q.sx;
  const T yy = q.cy * q.cy + q.sy * q.sy;
  w.E_v2 = xx + yy;
  w.R_v2 = xx - yy;
  w.S_v2 = T(2) * (q.cx * q.cy + q.sx * q.sy);
  w.Q_v2 = T(2) * (q.cx * q.sy - q.cy * q.sx);
  if (!(w.E_v2 > T(0))) return w;
  // a_A^2 - a_B^2 = sqrt(R^2 + S^2); a_B from Q keeps its sign and avoids the
  // cancellation of sqrt(E - N) when a_B << a_A.
  const T n = std::hypot(w.R_v2, w.S_v2);
  w.a_A_v = std::sqrt((w.E_v2 + n) / T(2));
  w.a_B_v = w.a_A_v > T(0) ? w.Q_v2 / (T(2) * w.a_A_v) : T(0);
  w.theta_A_rad = std::atan2(w.S_v2, w.R_v2) / T(4);
  const T l = q.cx * q.cx + q.cy * q.cy - q.sx * q.sx - q.sy * q.sy;
  const T p = T(2) * (q.cx * q.sx + q.cy * q.sy);
  w.phase_rad = std::atan2(-p, l) / T(2);
  return w;
}

// Inverse of wave_variables: the quadratures of a pattern (a_A, a_B, theta_A,
// phi) in the convention above. For tests, the simulator and the audit tool.
template <typename T>
Quadratures<T> quadratures_of_wave(T a_A, T a_B, T theta_A_rad, T phase_rad) {
  const T c2 = std::cos(T(2) * theta_A_rad);
  const T s2 = std::sin(T(2) * theta_A_rad);
  const T cp = std::cos(phase_rad);
  const T sp = std::sin(phase_rad);
  Quadratures<T> q;
  q.cx = a_A * c2 * cp - a_B * s2 * sp;
  q.sx = -a_A * c2 * sp - a_B * s2 * cp;
  q.cy = a_A * s2 * cp + a_B * c2 * sp;
  q.sy = -a_A * s2 * sp + a_B * c2 * cp;
  return q;
}

// Quadratures of complex envelopes x = Re(X e^{iwt}), y = Re(Y e^{iwt})
// (physics.md: X = cx - i sx, Y = cy - i sy), e.g. the simulator's analytic
// envelopes.
template <typename T>
Quadratures<T> quadratures_of_envelopes(std::complex<T> x_env, std::complex<T> y_env) {
  return Quadratures<T>{x_env.real(), -x_env.imag(), y_env.real(), -y_env.imag()};
}

// Keeps theta_A continuous through any number of turns. The wrapped angle has
// period pi/2 (the 4theta circle); the unwrapper counts quarter turns in an
// integer so the result keeps full precision after many turns (a float sum
// would not). Assumes |theta change| < pi/4 between calls (at 1 kHz that is
// 45000 deg/s of pattern rate).
template <typename T>
class ThetaUnwrapper {
  static_assert(std::is_floating_point_v<T>, "unwrapper is float or double");

 public:
  static constexpr T kPeriodRad = std::numbers::pi_v<T> / T(2);

  // Forgets the history; the next update() returns its argument unchanged.
  void reset() {
    started_ = false;
    quarter_turns_ = 0;
    last_wrapped_rad_ = T(0);
  }

  // theta_wrapped_rad: atan2(S, R) / 4, in [-pi/4, pi/4]. Returns the
  // continuous angle: theta_wrapped_rad + quarter_turns() * pi/2.
  T update(T theta_wrapped_rad) {
    if (started_) {
      const T d = theta_wrapped_rad - last_wrapped_rad_;
      if (d > kPeriodRad / T(2)) {
        --quarter_turns_;
      } else if (d < -kPeriodRad / T(2)) {
        ++quarter_turns_;
      }
    }
    started_ = true;
    last_wrapped_rad_ = theta_wrapped_rad;
    return value();
  }

  // Continuous angle, radians. In double this is exact to ~1e-16 relative.
  T value() const { return last_wrapped_rad_ + static_cast<T>(quarter_turns_) * kPeriodRad; }
  // Continuous angle in double regardless of T (for long runs in float).
  double value_f64() const {
    return static_cast<double>(last_wrapped_rad_) +
           static_cast<double>(quarter_turns_) * (std::numbers::pi / 2.0);
  }
  int64_t quarter_turns() const { return quarter_turns_; }

 private:
  bool started_ = false;
  int64_t quarter_turns_ = 0;
  T last_wrapped_rad_{0};
};

}  // namespace hrg::dsp
