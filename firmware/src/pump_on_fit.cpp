// SPDX-License-Identifier: MIT
#include "firmware/pump_on_fit.hpp"

#include <algorithm>

namespace hrg::fw {

namespace {
using Mat3 = std::array<std::array<double, 3>, 3>;

double dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

std::array<double, 3> times(const Mat3& m, const std::array<double, 3>& v) {
  return {dot(m[0], v), dot(m[1], v), dot(m[2], v)};
}

// The inverse of the fit's normal matrix: the line's (2x2, the third row and
// column 0) where q adds nothing beyond a line in t, else the full 3x3.
Mat3 normal_inverse(const std::array<double, 6>& s, bool with_q) {
  const double n = s[0], t = s[1], q = s[2], tt = s[3], tq = s[4], qq = s[5];
  Mat3 inv{};
  if (!with_q) {
    const double det = n * tt - t * t;
    inv[0] = {tt / det, -t / det, 0.0};
    inv[1] = {-t / det, n / det, 0.0};
    return inv;
  }
  const double c00 = tt * qq - tq * tq, c01 = -(t * qq - tq * q), c02 = t * tq - tt * q;
  const double det = n * c00 + t * c01 + q * c02;
  const double c11 = n * qq - q * q, c12 = -(n * tq - t * q), c22 = n * tt - t * t;
  inv[0] = {c00 / det, c01 / det, c02 / det};
  inv[1] = {c01 / det, c11 / det, c12 / det};
  inv[2] = {c02 / det, c12 / det, c22 / det};
  return inv;
}
}  // namespace

void PumpOnFit::add(double t, const std::array<double, 4>& q, double p_re, double p_im) {
  const std::array<double, kSeries> y{q[0], q[1], q[2], q[3], p_re, p_im};
  const double p2 = p_re * p_re + p_im * p_im;
  if (n_ == 0.0) {
    ref_ = y;  // sums of differences from the first row: no cancellation
  } else {
    q_ += 0.5 * (last_p2_ + p2) * (t - last_t_);
  }
  last_p2_ = p2;
  last_t_ = t;
  n_ += 1.0;
  const std::array<double, 3> a{1.0, t, q_};
  aa_[0] += 1.0;
  aa_[1] += t;
  aa_[2] += q_;
  aa_[3] += t * t;
  aa_[4] += t * q_;
  aa_[5] += q_ * q_;
  std::array<double, kSeries> d{};
  for (std::size_t s = 0; s < kSeries; ++s) {
    d[s] = y[s] - ref_[s];
    for (std::size_t j = 0; j < 3; ++j)
      ay_[s][j] += a[j] * d[s];
    yy_[s] += d[s] * d[s];
  }
  for (std::size_t c = 0; c < 4; ++c) {
    yp_[c][0] += d[c] * d[4];
    yp_[c][1] += d[c] * d[5];
  }
}

PumpOnFit::Result PumpOnFit::at(double t_e, bool bend) const {
  Result out;
  if (n_ < 3.0) return out;
  const double n = aa_[0], t = aa_[1], q = aa_[2], tt = aa_[3], tq = aa_[4], qq = aa_[5];
  // q about its own line in t (Schur complement): 0 when the pump held one level.
  const double det2 = n * tt - t * t;
  const double q_about_line = qq - (q * q * tt - 2.0 * q * t * tq + tq * tq * n) / det2;
  const double q_about_mean = qq - q * q / n;
  const bool with_q = bend && n_ >= 5.0 && q_about_mean > 0.0 && q_about_line > 1e-9 * q_about_mean;
  out.parameters = with_q ? 3 : 2;
  const Mat3 inv = normal_inverse(aa_, with_q);
  // After the last row the pump holds its level until the switch instant.
  const std::array<double, 3> x_e{1.0, t_e, q_ + last_p2_ * (t_e - last_t_)};
  const std::array<double, 3> u = times(inv, x_e);
  out.var_factor = dot(u, x_e);
  std::array<double, kSeries> rss{};
  std::array<std::array<double, 3>, kSeries> beta{};
  for (std::size_t s = 0; s < kSeries; ++s) {
    beta[s] = times(inv, ay_[s]);
    rss[s] = std::max(0.0, yy_[s] - dot(beta[s], ay_[s]));
  }
  for (std::size_t c = 0; c < 4; ++c) {
    out.v[c] = ref_[c] + dot(u, ay_[c]);
    out.rss += rss[c];
  }
  out.pump_re_v = ref_[4] + dot(u, ay_[4]);
  out.pump_im_v = ref_[5] + dot(u, ay_[5]);
  // Residual cross sums: sum e_u e_v = sum d_u d_v - beta_u . (A^T d_v).
  const auto cross = [&](std::size_t c, std::size_t j) {
    return yp_[c][j] - dot(beta[c], ay_[4 + j]);
  };
  for (std::size_t ch = 0; ch < 2; ++ch) {
    const std::size_t cx = 2 * ch;
    const std::size_t sx = cx + 1;
    // cx - Re(r P) and sx + Im(r P), squared and summed (rss_without_feedthrough).
    out.b[ch] = cross(sx, 1) - cross(cx, 0);
    out.c[ch] = cross(cx, 1) + cross(sx, 0);
  }
  out.pump_rss = rss[4] + rss[5];
  return out;
}

double PumpOnFit::rss_without_feedthrough(const Result& fit, const std::array<double, 4>& r) {
  double rss = fit.rss;
  for (std::size_t ch = 0; ch < 2; ++ch) {
    const double re = r[2 * ch];
    const double im = r[2 * ch + 1];
    rss += 2.0 * (re * fit.b[ch] + im * fit.c[ch]) + (re * re + im * im) * fit.pump_rss;
  }
  return std::max(0.0, rss);
}

}  // namespace hrg::fw
