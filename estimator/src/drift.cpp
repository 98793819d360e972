// SPDX-License-Identifier: MIT
#include <estimator/drift.hpp>

#include <cmath>

namespace hrg::est {

double resonator_drift_rad_s(const ParamVector& p, double theta_A_rad, double aB_over_aA) {
  const double s4 = std::sin(4.0 * theta_A_rad);
  const double c4 = std::cos(4.0 * theta_A_rad);
  const double q = aB_over_aA;
  const double d_nu = p(kDnuC) * s4 - p(kDnuS) * c4;  // nu dmu sin 4(th - th_mu)
  const double w_cos = p(kDwC) * c4 + p(kDwS) * s4;   // dw cos 4(th - th_w)
  return (d_nu * (1.0 + q * q) - 2.0 * q * w_cos) / (1.0 - q * q);
}

double DriftCompensator::step(double theta_A_rad, double aB_over_aA, double d_phi_rad_s,
                              double dt_s) {
  const double d =
      (have_model_ ? resonator_drift_rad_s(p_, theta_A_rad, aB_over_aA) : 0.0) + d_phi_rad_s;
  const double rate = d / k_;
  // Trapezoid on the rate: a model update changes the slope, never the value.
  correction_rad_ += 0.5 * dt_s * ((have_rate_ ? rate_rad_s_ : rate) + rate);
  rate_rad_s_ = rate;
  have_rate_ = true;
  return correction_rad_;
}

void ControlDriftEstimator::restart() {
  acc_ = Block{};
  have_prev_ = false;
  started_ = false;
}

bool ControlDriftEstimator::add_sample(const Sample& s) {
  if (!std::isfinite(s.t_s) || !std::isfinite(s.a_A_v) || !(s.a_A_v > 0) ||
      !std::isfinite(s.a_B_v) || !std::isfinite(s.pump_phase_error_rad) ||
      (started_ && !(s.t_s > t_last_s_))) {
    restart();
    return false;
  }
  if (!started_) {
    started_ = true;
    t_block_start_s_ = s.t_s;
  }
  t_last_s_ = s.t_s;
  acc_.t += s.t_s;
  acc_.aA += s.a_A_v;
  acc_.aB += s.a_B_v;
  acc_.c4 += std::cos(4.0 * s.theta_A_rad);
  acc_.s4 += std::sin(4.0 * s.theta_A_rad);
  acc_.tan_eps += std::tan(s.pump_phase_error_rad);
  acc_.qs += s.quad_force_sin_v_s;
  acc_.qc += s.quad_force_cos_v_s;
  ++acc_.n;
  if (s.t_s - t_block_start_s_ < config_.block_s) return true;

  Block b = acc_;
  const double inv = 1.0 / b.n;
  b.t *= inv;
  b.aA *= inv;
  b.aB *= inv;
  b.c4 *= inv;
  b.s4 *= inv;
  b.tan_eps *= inv;
  b.qs *= inv;
  b.qc *= inv;
  acc_ = Block{};
  t_block_start_s_ = s.t_s;
  if (have_prev_) {
    // Evaluate at the midpoint of the two block centres.
    const double dt = b.t - prev_.t;
    const double aA = 0.5 * (b.aA + prev_.aA);
    const double aB = 0.5 * (b.aB + prev_.aB);
    const double c4 = 0.5 * (b.c4 + prev_.c4);
    const double s4 = 0.5 * (b.s4 + prev_.s4);
    const double tan_eps = 0.5 * (b.tan_eps + prev_.tan_eps);
    const double dnu = p_(kDnuC) * c4 + p_(kDnuS) * s4;
    const double g = p_(kDwC) * s4 - p_(kDwS) * c4;
    const double fA = (b.aA - prev_.aA) / dt + (p_(kNu) + dnu) * aA + g * aB;
    const double fB = (b.aB - prev_.aB) / dt + (p_(kNu) - dnu) * aB - g * aA;
    const double qs = 0.5 * (b.qs + prev_.qs);
    const double qc = 0.5 * (b.qc + prev_.qc);
    const double fA_cos = fA * tan_eps;
    const double fB_cos = (fB - qs) * tan_eps + qc;
    const double d = -fB_cos / aA + (aB / aA) * fA_cos / aA;
    if (!have_estimate_) {
      d_phi_rad_s_ = d;
      have_estimate_ = true;
    } else {
      const double alpha = 1.0 - std::exp(-dt / config_.smoothing_s);
      d_phi_rad_s_ += alpha * (d - d_phi_rad_s_);
    }
  }
  prev_ = b;
  have_prev_ = true;
  return true;
}

}  // namespace hrg::est
