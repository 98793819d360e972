// SPDX-License-Identifier: MIT
#include "model.hpp"

#include <cmath>
#include <initializer_list>
#include <numbers>

#include <Eigen/Dense>

#include "dsp/wave_variables.hpp"

namespace hrg::audit::detail {

namespace {

constexpr double kPi = std::numbers::pi;
const cplx kI(0.0, 1.0);

Mat2 mul(const Mat2& a, const Mat2& b) {
  return {a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3], a[2] * b[0] + a[3] * b[2],
          a[2] * b[1] + a[3] * b[3]};
}

struct Inputs {
  double rate_rad_s, temp_c, a2_v2, theta_rad, t_s;
  double q_v2 = 0.0;  // the true vibration's quadrature Q = 2 a_A a_B (V^2), duffing_quadrature_v2
};

bool any_of(const Params& p, std::initializer_list<int> idx) {
  for (int i : idx)
    if (p[static_cast<std::size_t>(i)] != 0.0) return true;
  return false;
}

// Generic frequency (rad/s) and damping scale terms of the description.
void generic_terms(const Params& p, const Dataset& d, const Inputs& in, double& dw, double& s) {
  const double dT = in.temp_c - d.temp_ref_c;
  const double a4 = in.a2_v2 * in.a2_v2;
  const double th = (in.t_s - d.t_mid_s) / 3600.0;
  const double c8 = std::cos(8.0 * in.theta_rad), s8 = std::sin(8.0 * in.theta_rad);
  dw = 2.0 * kPi *
       (p[kGFreqA4] * a4 + d.f_ref_hz * 1e-6 * p[kGFreqT2] * dT * dT + p[kGFreqTime] * th +
        p[kGFreq8C] * c8 + p[kGFreq8S] * s8);
  s = (1.0 + p[kGDampA4] * a4) * (1.0 + p[kGDampT2] * dT * dT) * (1.0 + p[kGDampTime] * th) *
      (1.0 + p[kGDamp8C] * c8 + p[kGDamp8S] * s8);
}

// Dynamics matrix of the model for one set of slow inputs.
Mat2 dynamics(const Params& p, const Dataset& d, const Inputs& in) {
  const double dT = in.temp_c - d.temp_ref_c;
  // Both circular modes of eq. 1 ring at sqrt(w^2 + (Omega K)^2) -+ Omega K:
  // the common second-order shift (Omega K)^2 / 2w moves the phase.
  const double ok2 = in.rate_rad_s * p[kK] * in.rate_rad_s * p[kK];
  const double dw0 = p[kDw0] + p[kCor] * ok2 / (4.0 * kPi * d.f_ref_hz) +
                     2.0 * kPi * p[kDuff] * in.a2_v2 + 2.0 * kPi * d.f_ref_hz * 1e-6 * p[kTf] * dT;
  double s = (1.0 + p[kNld] * in.a2_v2) * (1.0 + p[kTd] * dT);
  double dw = 0.0;
  if (any_of(p, {kGFreqA4, kGDampA4, kGFreqT2, kGDampT2, kGFreqTime, kGDampTime, kGDamp8C, kGDamp8S,
                 kGFreq8C, kGFreq8S})) {
    double sg = 1.0;
    generic_terms(p, d, in, dw, sg);
    s *= sg;
  }
  // A Duffing term turns the pattern through the quadrature (the cubic force's
  // averaged part along conj(Z) acts on a_B at a third of its action on a_A):
  // 2 theta' = -(2/3) 2 pi c a_A a_B, a rotation like the rate's. Left out,
  // the free decays' quadrature, which grows with the split, drifted the
  // pattern by ~2e-5 rad/s there (c -3e-3 Hz/V^2, split 1.2 mHz) and the
  // segments, held at a_B ~ 0, read the difference as a gap harmonic.
  const double ok = in.rate_rad_s * p[kK] + 2.0 * kPi / 3.0 * p[kDuff] * in.q_v2;
  return {kI * (dw0 + dw + p[kDwC]) - s * (p[kNu] + p[kDnuC]), kI * p[kDwS] - s * p[kDnuS] + ok,
          kI * p[kDwS] - s * p[kDnuS] - ok, kI * (dw0 + dw - p[kDwC]) - s * (p[kNu] - p[kDnuC])};
}

// Pickoff chain: X_m = X, Y_m = (1+g) e^{-i phi} (Y cos2b + X sin2b), with
// the generic drifts of g and phi in time and of g with temperature.
Mat2 pickoff(const Params& p, double dgain = 0.0, double dphase = 0.0) {
  const cplx gy = (1.0 + p[kGain] + dgain) * std::polar(1.0, -(p[kPhase] + dphase));
  return {1.0, 0.0, gy * std::sin(2.0 * p[kMis]), gy * std::cos(2.0 * p[kMis])};
}

bool pickoff_varies(const Params& p) { return any_of(p, {kGGainTime, kGPhaseTime, kGGainTemp}); }

Mat2 pickoff_at(const Params& p, const Dataset& d, const Block& b) {
  const double th = (b.t_s - d.t_mid_s) / 3600.0;
  return pickoff(p, p[kGGainTime] * th + p[kGGainTemp] * (b.temp_c - d.temp_ref_c),
                 p[kGPhaseTime] * th);
}

// Mean of exp(A tau) over the block's sample times (central moments m2..m4).
Mat2 block_mean(const Mat2& a, const Block& b) {
  const Mat2 a2 = mul(a, a);
  const Mat2 a3 = mul(a2, a);
  const Mat2 a4 = mul(a2, a2);
  Mat2 m;
  for (int k = 0; k < 4; ++k) {
    m[k] = a2[k] * (b.m2 / 2.0) + a3[k] * (b.m3 / 6.0) + a4[k] * (b.m4 / 24.0);
  }
  m[0] += 1.0;
  m[3] += 1.0;
  return m;
}

// The true vibration's quadrature Q = 2 a_A a_B = -2 Im(conj(X) Y) (V^2) of block
// b, its mean envelopes through the inverse of the pickoff map (a phase
// mismatch phi alone reads a standing vibration with Q = a^2 sin 4theta sin phi:
// 0.017 a^2 at 1 deg, twice what the other resonator's split grows in a 1 s
// free decay). Only a Duffing term uses it.
double duffing_quadrature_v2(const Params& p, const Block& b) {
  if (p[kDuff] == 0.0) return 0.0;
  const Mat2 c = pickoff(p);
  const cplx x = b.x - cplx(p[kGOffXRe], p[kGOffXIm]) * b.rot;
  const cplx y = (b.y - cplx(p[kGOffYRe], p[kGOffYIm]) * b.rot - c[2] * x) / c[3];
  return -2.0 * (std::conj(x) * y).imag();
}

Inputs inputs_of(const Params& p, const Block& b) {
  return {b.rate_rad_s, b.temp_c, b.a2_v2, b.theta_rad, b.t_s, duffing_quadrature_v2(p, b)};
}
Inputs mid_inputs(const Params& p, const Block& a, const Block& b) {
  return {0.5 * (a.rate_rad_s + b.rate_rad_s),
          0.5 * (a.temp_c + b.temp_c),
          0.5 * (a.a2_v2 + b.a2_v2),
          0.5 * (a.theta_rad + b.theta_rad),
          0.5 * (a.t_s + b.t_s),
          0.5 * (duffing_quadrature_v2(p, a) + duffing_quadrature_v2(p, b))};
}

// Block operators G_b = C M_b Phi_b of one segment.
void segment_operators(const Dataset& d, const Params& p, const FreeSegment& s,
                       std::vector<Mat2>& g) {
  const Mat2 c0 = pickoff(p);
  const bool varies = pickoff_varies(p);
  g.resize(s.n_blocks);
  Mat2 phi{1.0, 0.0, 0.0, 1.0};
  for (std::size_t k = 0; k < s.n_blocks; ++k) {
    const Block& b = d.blocks[s.first_block + k];
    if (k > 0) {
      const Block& prev = d.blocks[s.first_block + k - 1];
      phi = mul(expm2(dynamics(p, d, mid_inputs(p, prev, b)), b.t_s - prev.t_s), phi);
    }
    const Mat2 c = varies ? pickoff_at(p, d, b) : c0;
    g[k] = mul(c, mul(block_mean(dynamics(p, d, inputs_of(p, b)), b), phi));
  }
}

// Generic constant offsets of the x and y pickoffs (X = cx - i sx) as they
// appear in the block means of the derotated envelopes.
std::array<cplx, 2> offsets(const Params& p, const Block& b) {
  return {cplx(p[kGOffXRe], p[kGOffXIm]) * b.rot, cplx(p[kGOffYRe], p[kGOffYIm]) * b.rot};
}

// Least-squares initial state over blocks [k0, k1).
std::array<cplx, 2> solve_state(const Dataset& d, const Params& p, const FreeSegment& s,
                                const std::vector<Mat2>& g, std::size_t k0, std::size_t k1) {
  cplx n00 = 0, n01 = 0, n11 = 0, r0 = 0, r1 = 0;
  for (std::size_t k = k0; k < k1; ++k) {
    const Block& b = d.blocks[s.first_block + k];
    const Mat2& m = g[k];
    // N = sum n G^H G, r = sum n G^H y
    n00 += b.n * (std::conj(m[0]) * m[0] + std::conj(m[2]) * m[2]);
    n01 += b.n * (std::conj(m[0]) * m[1] + std::conj(m[2]) * m[3]);
    n11 += b.n * (std::conj(m[1]) * m[1] + std::conj(m[3]) * m[3]);
    const auto off = offsets(p, b);
    const cplx bx = b.x - off[0], by = b.y - off[1];
    r0 += b.n * (std::conj(m[0]) * bx + std::conj(m[2]) * by);
    r1 += b.n * (std::conj(m[1]) * bx + std::conj(m[3]) * by);
  }
  const cplx n10 = std::conj(n01);
  const cplx det = n00 * n11 - n01 * n10;
  if (std::abs(det) == 0.0) return {0.0, 0.0};
  return {(n11 * r0 - n01 * r1) / det, (n00 * r1 - n10 * r0) / det};
}

// Phase of the measured wave of a pure standing wave at angle theta.
double measured_phase(const Params& p, double theta) {
  const Mat2 c = pickoff(p);
  const cplx x = c[0] * std::cos(2.0 * theta) + c[1] * std::sin(2.0 * theta);
  const cplx y = c[2] * std::cos(2.0 * theta) + c[3] * std::sin(2.0 * theta);
  return dsp::wave_variables<double>({x.real(), -x.imag(), y.real(), -y.imag()}).phase_rad;
}

// The pump follows the measured phase of the vibration (the firmware's PLL
// locks on it and the pump runs at a fixed phase from it), which the pickoff
// map turns off the true one by delta(theta) = measured_phase(p, theta) (a
// phase mismatch phi: about -phi sin^2 2theta; a gain or a misalignment
// leaves a standing vibration's phase alone). Its parametric drive is then 2
// delta off its best phase and pulls the true frequency by (a_A'/a_A + nu)
// sin 2 delta (physics.md section 4; the same pull as a drive feedthrough's,
// pump_phase_pull), weighted by the pump's drive V^2 over the segment. To
// first order delta is a mean and a 4-theta harmonic: both from three
// angles. Held (a_A'/a_A ~ 0) a phase mismatch of 1.5 deg pulls by ~0.026 nu
// (1 - cos 4 theta); a ring-up by tens of that.
double pickoff_pump_pull(const ForcedSegment& f, const Params& p) {
  if (!(f.mean_v2 > 0.0) || p[kPhase] == 0.0) return 0.0;
  const double d0 = std::remainder(measured_phase(p, 0.0), kPi);
  const double d8 = std::remainder(measured_phase(p, kPi / 8.0), kPi);
  const double d4 = std::remainder(measured_phase(p, kPi / 4.0), kPi);
  const double mean = 0.5 * (d0 + d4), c4 = 0.5 * (d0 - d4), s4 = d8 - mean;
  const double delta_v2 = mean * f.mean_v2 + c4 * f.mean_v2c4 + s4 * f.mean_v2s4;
  return 2.0 * (true_growth_per_s(f, p) + p[kNu]) * delta_v2 / f.mean_v2;
}

}  // namespace

double param_scale(int p) {
  static constexpr double kScale[kParamCount] = {
      1e-3, 1e-3, 1e-4, 1e-4, 1e-4, 1e-4, 1e-3, 1e-3, 1e-3, 1e-3, 1e-4, 1e-3,
      1e-1, 1e-3, 1e-6, 1e-2, 1e-2, 1e-1, 1e-4, 1e-3, 1e-1, 1e-3, 1e-4, 1e-2,
      1e-3, 1e-3, 1e-5, 1e-5, 1e-3, 1e-3, 1e-3, 1e-5, 1e-5, 1e-5, 1e-5, 1e-4};
  return kScale[p];
}

Mat2 expm2(const Mat2& a, double t) {
  const cplx tr = 0.5 * (a[0] + a[3]);
  const Mat2 b{(a[0] - tr) * t, a[1] * t, a[2] * t, (a[3] - tr) * t};
  const cplx s2 = b[0] * b[0] + b[1] * b[2];
  const cplx s = std::sqrt(s2);
  cplx ch, shs;
  if (std::abs(s) < 1e-4) {
    ch = 1.0 + s2 / 2.0 + s2 * s2 / 24.0;
    shs = 1.0 + s2 / 6.0 + s2 * s2 / 120.0;
  } else {
    ch = std::cosh(s);
    shs = std::sinh(s) / s;
  }
  const cplx e = std::exp(tr * t);
  return {e * (ch + shs * b[0]), e * shs * b[1], e * shs * b[2], e * (ch + shs * b[3])};
}

std::vector<double> forced_residuals(const Dataset& d, const Params& p) {
  std::vector<double> r;
  r.reserve(d.forced.size());
  for (const auto& f : d.forced) {
    const double dT = f.mean_temp_c - d.temp_ref_c;
    const double okf = f.mean_rate_rad_s * p[kK];
    double w =
        p[kDw0] + p[kCor] * okf * okf / (4.0 * kPi * d.f_ref_hz) + p[kDwC] * f.mean_c4 +
        p[kDwS] * f.mean_s4 + 2.0 * kPi * p[kDuff] * f.mean_a2 +
        2.0 * kPi * d.f_ref_hz * 1e-6 * p[kTf] * dT +
        2.0 * kPi * p[kEs] * (f.mean_v2 + 0.5 * (p[kGapP] * f.mean_v2c4 + p[kGapQ] * f.mean_v2s4)) +
        2.0 * kPi * p[kGFreqExc];
    if (any_of(p, {kGFreqA4, kGFreqT2, kGFreqTime, kGFreq8C, kGFreq8S})) {
      double dw = 0.0, sg = 1.0;
      generic_terms(p, d,
                    {f.mean_rate_rad_s, f.mean_temp_c, f.mean_a2,
                     0.5 * (f.theta0_rad + f.theta1_rad), 0.5 * (f.t0_s + f.t1_s)},
                    dw, sg);
      w += dw;
    }
    // The readout's change between the rows the measured phase averages.
    const double dm = f.end_change([&p](double th0, double th1) {
      return std::remainder(measured_phase(p, th1) - measured_phase(p, th0), kPi);
    });
    w += dm / (f.t1_s - f.t0_s) + pickoff_pump_pull(f, p);
    r.push_back(f.freq_rad_s - w);
  }
  return r;
}

double pump_phase_pull(const ForcedSegment& f, const std::array<double, 4>& c, double nu_per_s) {
  if (!(f.mean_v2 > 0.0)) return 0.0;
  const double growth_per_v2 = (f.dlna_per_s + nu_per_s) / f.mean_v2;
  return 2.0 * growth_per_v2 * (c[1] * f.ft_hx_v2 + c[3] * f.ft_hy_v2);
}

namespace {
// Pattern angle and amplitude the pickoff map shows for a standing wave of
// unit amplitude at theta.
dsp::WaveVariables<double> measured_wave(const Params& p, double theta) {
  const Mat2 c = pickoff(p);
  const cplx x = c[0] * std::cos(2.0 * theta) + c[1] * std::sin(2.0 * theta);
  const cplx y = c[2] * std::cos(2.0 * theta) + c[3] * std::sin(2.0 * theta);
  return dsp::wave_variables<double>({x.real(), -x.imag(), y.real(), -y.imag()});
}
double measured_theta(const Params& p, double theta) {
  return theta + std::remainder(measured_wave(p, theta).theta_A_rad - theta, kPi / 2.0);
}
}  // namespace

double true_growth_per_s(const ForcedSegment& f, const Params& p) {
  if (!any_of(p, {kGain, kMis})) return f.dlna_per_s;
  const double readout = f.end_change([&p](double th0, double th1) {
    return std::log(measured_wave(p, th1).a_A_v / measured_wave(p, th0).a_A_v);
  });
  return f.dlna_per_s - readout / (f.t1_s - f.t0_s);
}

std::vector<double> balance_left(const Dataset& d, const Params& p) {
  std::vector<double> left;
  left.reserve(d.forced.size());
  for (const auto& f : d.forced) {
    const double dT = f.mean_temp_c - d.temp_ref_c;
    const double s = (1.0 + p[kNld] * f.mean_a2) * (1.0 + p[kTd] * dT);
    left.push_back(true_growth_per_s(f, p) +
                   s * (p[kNu] + p[kDnuC] * f.mean_c4 + p[kDnuS] * f.mean_s4));
  }
  return left;
}

namespace {
// Mean of V^2 (1 + eps_p/2 c4 + eps_q/2 s4) over segment f: the pump's drive.
double pump_drive_v2(const ForcedSegment& f, const Params& p) {
  return f.mean_v2 + 0.5 * (p[kGapP] * f.mean_v2c4 + p[kGapQ] * f.mean_v2s4);
}
}  // namespace

PumpGain balance_pump_gain(const Dataset& d, const Params& p, const std::vector<double>& left) {
  // Weighted least squares of left = (c0 + c1 a_A'/a_A) M over the segments
  // that recover, c_settled M over those that hold among them.
  Eigen::Matrix3d n = Eigen::Matrix3d::Zero();
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  bool any_settled = false;
  for (std::size_t i = 0; i < d.forced.size(); ++i) {
    const ForcedSegment& f = d.forced[i];
    if (!(f.balance_sigma_per_s > 0.0)) continue;
    const double w = 1.0 / (f.balance_sigma_per_s * f.balance_sigma_per_s);
    const double m = pump_drive_v2(f, p);
    const Eigen::Vector3d h = f.pump_settled ? Eigen::Vector3d(0.0, 0.0, m)
                                             : Eigen::Vector3d(m, true_growth_per_s(f, p) * m, 0.0);
    any_settled = any_settled || f.pump_settled;
    n += w * h * h.transpose();
    r += w * left[i] * h;
  }
  PumpGain c;
  const double det = n(0, 0) * n(1, 1) - n(0, 1) * n(0, 1);
  if (det > 1e-12 * n(0, 0) * n(1, 1)) {
    c.c0 = (n(1, 1) * r(0) - n(0, 1) * r(1)) / det;
    c.c1 = (n(0, 0) * r(1) - n(0, 1) * r(0)) / det;
  } else if (n(0, 0) > 0.0) {
    c.c0 = r(0) / n(0, 0);
  }
  c.c_settled = any_settled ? r(2) / n(2, 2) : c.c0;
  return c;
}

std::vector<double> balance_residuals(const Dataset& d, const Params& p) {
  std::vector<double> r;
  const std::vector<double> left = balance_left(d, p);
  const PumpGain c = balance_pump_gain(d, p, left);
  for (std::size_t i = 0; i < d.forced.size(); ++i) {
    const ForcedSegment& f = d.forced[i];
    if (f.balance_sigma_per_s > 0.0)
      r.push_back(left[i] - c.at(f, true_growth_per_s(f, p)) * pump_drive_v2(f, p));
  }
  return r;
}

std::vector<double> angle_residuals(const Dataset& d, const Params& p) {
  std::vector<double> r;
  const std::vector<double> left = balance_left(d, p);
  const PumpGain gain = balance_pump_gain(d, p, left);
  for (const auto& f : d.forced) {
    if (!(f.angle_sigma_rad_s > 0.0)) continue;
    const double c = gain.at(f, true_growth_per_s(f, p));
    const double dT = f.mean_temp_c - d.temp_ref_c;
    const double s = (1.0 + p[kNld] * f.mean_a2) * (1.0 + p[kTd] * dT);
    const double drift = s * (p[kDnuC] * f.mean_s4 - p[kDnuS] * f.mean_c4) +
                         0.5 * c * (p[kGapQ] * f.mean_v2c4 - p[kGapP] * f.mean_v2s4);
    const double t = f.angle_span_s;
    const double readout = (measured_theta(p, f.theta1_rad) - f.theta1_rad) -
                           (measured_theta(p, f.theta0_rad) - f.theta0_rad);
    r.push_back((f.theta1_rad - f.theta0_rad - readout) / t - f.angle_pull_rad_s -
                0.5 * (drift - p[kK] * f.angle_rate_rad_s));
  }
  return r;
}

void evaluate(const Dataset& d, const Params& p, const EvalOptions& o, std::vector<double>& res,
              std::vector<std::array<cplx, 2>>* pred) {
  res.clear();
  if (pred) pred->assign(d.blocks.size(), {cplx(0.0), cplx(0.0)});
  std::vector<Mat2> g;
  const double inv_sigma = 1.0 / d.noise_v;
  for (const auto& s : d.free) {
    if (o.heldout_only != s.heldout) {
      if (o.heldout_only || !o.include_heldout) continue;
    }
    segment_operators(d, p, s, g);
    std::size_t k_fit1 = s.n_blocks, k_res0 = 0;
    if (o.heldout_only) {
      k_fit1 = std::max<std::size_t>(2, s.n_blocks / 5);
      k_res0 = k_fit1;
    }
    const auto z = solve_state(d, p, s, g, 0, k_fit1);
    for (std::size_t k = k_res0; k < s.n_blocks; ++k) {
      const Block& b = d.blocks[s.first_block + k];
      const auto off = offsets(p, b);
      const cplx px = g[k][0] * z[0] + g[k][1] * z[1] + off[0];
      const cplx py = g[k][2] * z[0] + g[k][3] * z[1] + off[1];
      const double w = std::sqrt(b.n) * inv_sigma;
      res.push_back(w * (b.x - px).real());
      res.push_back(w * (b.x - px).imag());
      res.push_back(w * (b.y - py).real());
      res.push_back(w * (b.y - py).imag());
      if (pred) (*pred)[s.first_block + k] = {px, py};
    }
  }
  if (o.use_forced && !o.heldout_only) {
    const auto fr = forced_residuals(d, p);
    for (std::size_t i = 0; i < fr.size(); ++i)
      res.push_back(fr[i] / d.forced[i].sigma_rad_s);
    const auto br = balance_residuals(d, p);
    std::size_t k = 0;
    for (const auto& f : d.forced)
      if (f.balance_sigma_per_s > 0.0) res.push_back(br[k++] / f.balance_sigma_per_s);
    const auto ar = angle_residuals(d, p);
    k = 0;
    for (const auto& f : d.forced)
      if (f.angle_sigma_rad_s > 0.0) res.push_back(ar[k++] / f.angle_sigma_rad_s);
  }
}

std::vector<std::array<cplx, 2>> predict_rows(const Dataset& d, const Params& p, std::size_t seg,
                                              const std::vector<std::size_t>& rows,
                                              double* wave_phase_rad, double* theta_rad) {
  const FreeSegment& s = d.free[seg];
  std::vector<Mat2> g;
  segment_operators(d, p, s, g);
  const auto z0 = solve_state(d, p, s, g, 0, s.n_blocks);
  // Propagate the state to the last block for rows after the segment.
  Mat2 phi{1.0, 0.0, 0.0, 1.0};
  for (std::size_t k = 1; k < s.n_blocks; ++k) {
    const Block& a = d.blocks[s.first_block + k - 1];
    const Block& b = d.blocks[s.first_block + k];
    phi = mul(expm2(dynamics(p, d, mid_inputs(p, a, b)), b.t_s - a.t_s), phi);
  }
  const Block& first = d.blocks[s.first_block];
  const Block& last = d.blocks[s.first_block + s.n_blocks - 1];
  const std::array<cplx, 2> zl{phi[0] * z0[0] + phi[1] * z0[1], phi[2] * z0[0] + phi[3] * z0[1]};
  const Mat2 c = pickoff(p);
  std::vector<std::array<cplx, 2>> out;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double t = d.t_s[rows[i]];
    const bool before = t < first.t_s;
    const Block& ref = before ? first : last;
    const auto& zr = before ? z0 : zl;
    const Mat2 e = expm2(dynamics(p, d, inputs_of(p, ref)), t - ref.t_s);
    const cplx zx = e[0] * zr[0] + e[1] * zr[1];
    const cplx zy = e[2] * zr[0] + e[3] * zr[1];
    if (i == 0 && (wave_phase_rad || theta_rad)) {
      // Phase of the A wave with theta_A = atan2(S, R)/4 in (-pi/4, pi/4]: the
      // usual convention, so a drive that follows the wave keeps its sign.
      const double th =
          dsp::wave_variables<double>({zx.real(), -zx.imag(), zy.real(), -zy.imag()}).theta_A_rad;
      if (wave_phase_rad)
        *wave_phase_rad = std::arg(zx * std::cos(2.0 * th) + zy * std::sin(2.0 * th));
      if (theta_rad) *theta_rad = th;
    }
    const cplx rot = std::polar(1.0, d.frame_phase_rad[rows[i]]);
    out.push_back({c[0] * zx + c[1] * zy + cplx(p[kGOffXRe], p[kGOffXIm]) * rot,
                   c[2] * zx + c[3] * zy + cplx(p[kGOffYRe], p[kGOffYIm]) * rot});
  }
  return out;
}

}  // namespace hrg::audit::detail
