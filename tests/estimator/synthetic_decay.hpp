// SPDX-License-Identifier: MIT
#pragma once

// Free decay of the wave variables from the closed-form solution of eq. 8
// (docs/physics.md section 2), for the estimator's unit tests.
//
// With the pattern angle frozen over a step h, eq. 8 is
//   [a_A, a_B]' = (-nu I + M) [a_A, a_B],  M = [[-d, -g], [g, d]],
//   d = dnu_C cos4th + dnu_S sin4th,  g = dw_C sin4th - dw_S cos4th,
// and M^2 = (d^2 - g^2) I, so exp(M h) = ch(h) I + sh(h) M with
// ch = cosh(r h), sh = sinh(r h)/r for r^2 = d^2 - g^2 > 0 and cos/sin for < 0.
// The angle moves by theta' = (-K Omega + D)/2 with D = D_nu + D_w (eq. 7/22),
// taken at the step's midpoint. Noise is white on the four demodulated
// quadratures (dsp convention), and the wave variables are recomputed from
// them as the firmware does.

#include <cmath>
#include <random>

#include <estimator/drift.hpp>
#include <estimator/types.hpp>

#include <dsp/wave_variables.hpp>

namespace hrg::est::test {

struct DecayState {
  double t_s{0};
  double a_A_v{1.0};
  double a_B_v{0.0};
  double theta_rad{0.0};
};

class SyntheticDecay {
 public:
  SyntheticDecay(const ParamVector& p, double angular_gain, double rate_rad_s)
      : p_(p), k_(angular_gain), rate_(rate_rad_s) {}

  // Advances the true state by h seconds (exact for frozen theta).
  void step(DecayState& s, double h) const {
    const double th_mid = s.theta_rad + 0.5 * h * theta_rate(s);
    const double c4 = std::cos(4 * th_mid), s4 = std::sin(4 * th_mid);
    const double d = p_(kDnuC) * c4 + p_(kDnuS) * s4;
    const double g = p_(kDwC) * s4 - p_(kDwS) * c4;
    const double r2 = d * d - g * g;
    double ch, sh;
    if (r2 > 0) {
      const double r = std::sqrt(r2);
      ch = std::cosh(r * h);
      sh = std::sinh(r * h) / r;
    } else if (r2 < 0) {
      const double r = std::sqrt(-r2);
      ch = std::cos(r * h);
      sh = std::sin(r * h) / r;
    } else {
      ch = 1;
      sh = h;
    }
    const double e = std::exp(-p_(kNu) * h);
    const double a = e * ((ch - sh * d) * s.a_A_v - sh * g * s.a_B_v);
    const double b = e * (sh * g * s.a_A_v + (ch + sh * d) * s.a_B_v);
    // Midpoint angle rate with the midpoint state.
    DecayState mid = s;
    mid.theta_rad = th_mid;
    mid.a_A_v = 0.5 * (s.a_A_v + a);
    mid.a_B_v = 0.5 * (s.a_B_v + b);
    s.theta_rad += h * theta_rate(mid);
    s.a_A_v = a;
    s.a_B_v = b;
    s.t_s += h;
  }

  double theta_rate(const DecayState& s) const {
    return 0.5 * (-k_ * rate_ + resonator_drift_rad_s(p_, s.theta_rad, s.a_B_v / s.a_A_v));
  }

  // The measured sample: quadratures plus white noise, back to wave variables.
  template <typename Rng>
  WaveSample measure(const DecayState& s, double noise_v, Rng& rng, double phase_rad = 0.3) const {
    auto q = dsp::quadratures_of_wave<double>(s.a_A_v, s.a_B_v, s.theta_rad, phase_rad);
    if (noise_v > 0) {
      std::normal_distribution<double> n(0.0, noise_v);
      q.cx += n(rng);
      q.sx += n(rng);
      q.cy += n(rng);
      q.sy += n(rng);
    }
    const auto w = dsp::wave_variables<double>(q);
    return WaveSample{s.t_s, w.a_A_v, w.a_B_v, w.theta_A_rad, w.E_v2};
  }

 private:
  ParamVector p_;
  double k_;
  double rate_;
};

// Parameters of the seed's resonator (f 5 kHz, Q 5e6, dQ/Q 0.1 -> dmu 0.05,
// split 5e-4 Hz -> dw = pi * 5e-4 rad/s) with axes th_mu, th_w.
inline ParamVector seed_params(double th_mu_rad, double th_w_rad, double dmu = 0.05,
                               double split_hz = 5e-4) {
  const double nu = M_PI * 5000.0 / 5e6;
  const double dw = M_PI * split_hz;
  ParamVector p;
  p << nu, nu * dmu * std::cos(4 * th_mu_rad), nu * dmu * std::sin(4 * th_mu_rad),
      dw * std::cos(4 * th_w_rad), dw * std::sin(4 * th_w_rad);
  return p;
}

}  // namespace hrg::est::test
