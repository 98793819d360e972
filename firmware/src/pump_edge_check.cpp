// SPDX-License-Identifier: MIT
#include "firmware/pump_edge_check.hpp"

#include <algorithm>
#include <cmath>

namespace hrg::fw {

const char* to_string(PumpEdgeVerdict v) {
  switch (v) {
    case PumpEdgeVerdict::unknown: return "unknown";
    case PumpEdgeVerdict::consistent: return "consistent";
    case PumpEdgeVerdict::step: return "step";
  }
  return "?";
}

namespace {
std::array<double, 4> quadratures(const ChainRecord& r) {
  return {r.quad_v.cx, r.quad_v.sx, r.quad_v.cy, r.quad_v.sy};
}
}  // namespace

constexpr double kTwoPiOver2To32 = 6.283185307179586 / 4294967296.0;

PumpEdgeCheck::PumpEdgeCheck(const PumpEdgeCheckConfig& cfg) : cfg_(cfg) {
  cfg_.fit_rows = std::clamp<uint32_t>(cfg_.fit_rows, 3, kMaxFitRows);
  cfg_.row_centre_blocks = std::clamp(cfg_.row_centre_blocks, 0.0, 3.0);
  reset();
}

void PumpEdgeCheck::reset() {
  status_ = PumpEdgeStatus{};
  on_rows_ = 0;
  was_on_ = false;
  in_edge_ = false;
  weight_ = 0.0;
  max_pump_v_ = 0.0;
  weighted_r_ = {};
  weighted_rr_ = {};
  since_set_ = false;
}

void PumpEdgeCheck::LineSums::add(double t_row, const std::array<double, 4>& q) {
  n += 1.0;
  t += t_row;
  tt += t_row * t_row;
  for (std::size_t c = 0; c < 4; ++c) {
    y[c] += q[c];
    ty[c] += t_row * q[c];
    yy[c] += q[c] * q[c];
  }
}

PumpEdgeCheck::LineAt PumpEdgeCheck::line_at(const LineSums& s, double t_e) {
  LineAt out;
  const double t_mean = s.t / s.n;
  const double sxx = s.tt - s.n * t_mean * t_mean;
  const double d = t_e - t_mean;
  out.var_factor = 1.0 / s.n + d * d / sxx;
  for (std::size_t c = 0; c < 4; ++c) {
    const double y_mean = s.y[c] / s.n;
    const double sxy = s.ty[c] - s.n * t_mean * y_mean;
    const double slope = sxy / sxx;
    out.v[c] = y_mean + slope * d;
    // Residual sum of squares of the line: Syy - Sxy^2 / Sxx about the means.
    out.rss += std::max(0.0, s.yy[c] - s.n * y_mean * y_mean - slope * sxy);
  }
  return out;
}

uint32_t PumpEdgeCheck::centre_phase(uint32_t nco_phase_end) {
  end_pos_ = (end_pos_ + 1) % 4;
  end_phase_[end_pos_] = nco_phase_end;
  const double c = cfg_.row_centre_blocks;
  const auto k = static_cast<uint32_t>(std::min(2.0, std::floor(c)));
  const double frac = c - k;
  const uint32_t a = end_phase_[(end_pos_ + 4 - k) % 4];
  const uint32_t b = end_phase_[(end_pos_ + 3 - k) % 4];  // one block earlier
  const auto diff = static_cast<int32_t>(b - a);
  return a + static_cast<uint32_t>(static_cast<int32_t>(std::lround(frac * diff)));
}

std::array<double, 4> PumpEdgeCheck::in_frame(const std::array<double, 4>& q, uint32_t centre,
                                              double t) const {
  // X_frame = X e^{i d}, d the NCO's phase ahead of the frame (small).
  const auto rows = static_cast<int64_t>(std::llround(t));
  const uint32_t frame = frame_phase_ + static_cast<uint32_t>(rows) * frame_advance_;
  const double d = static_cast<double>(static_cast<int32_t>(centre - frame)) * kTwoPiOver2To32;
  const double c = std::cos(d);
  const double s = std::sin(d);
  return {q[0] * c + q[1] * s, q[1] * c - q[0] * s, q[2] * c + q[3] * s, q[3] * c - q[2] * s};
}

void PumpEdgeCheck::begin_edge() {
  // The last fit_rows pump-on rows, at t = -(n-1) .. 0 (0: the last one),
  // with the pump each saw (fw::PumpOnFit weighs the pump as it weighs them).
  PumpOnFit pre;
  const uint32_t n = cfg_.fit_rows;
  const uint32_t last = (ring_pos_ + kMaxFitRows - 1) % kMaxFitRows;
  frame_phase_ = ring_phase_[last];
  frame_advance_ = ring_phase_[last] - ring_phase_[(last + kMaxFitRows - 1) % kMaxFitRows];
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t i = (ring_pos_ + kMaxFitRows - n + k) % kMaxFitRows;
    const double t = static_cast<double>(k) - static_cast<double>(n - 1);
    // X += r P appears as cx += Re(rP), sx -= Im(rP): P turns as X does.
    const std::array<double, 4> p =
        in_frame({ring_pump_[i][0] * std::cos(ring_pump_[i][1]),
                  -ring_pump_[i][0] * std::sin(ring_pump_[i][1]), 0.0, 0.0},
                 ring_phase_[i], t);
    pre.add(t, in_frame(ring_[i], ring_phase_[i], t), p[0], -p[1]);
  }
  pre_line_ = pre.at(cfg_.edge_offset_rows, false);
  pre_bend_ = pre.at(cfg_.edge_offset_rows, true);
  amplitude_v_ = last_amplitude_v_;
  post_ = LineSums{};
  off_rows_ = 0;
  in_edge_ = true;
}

PumpEdgeCheck::Reading PumpEdgeCheck::read(const PumpOnFit::Result& pre, const LineAt& post) {
  Reading out;
  const double pr = pre.pump_re_v;
  const double pi = pre.pump_im_v;
  out.p2 = pr * pr + pi * pi;
  if (!(out.p2 > 0.0)) return out;
  // dX = d(cx) - i d(sx); r = -dX conj(P) / |P|^2.
  for (std::size_t c = 0; c < 4; c += 2) {
    const double d_re = post.v[c] - pre.v[c];
    const double d_im = -(post.v[c + 1] - pre.v[c + 1]);
    out.r[c] = -(d_re * pr + d_im * pi) / out.p2;
    out.r[c + 1] = -(d_im * pr - d_re * pi) / out.p2;
  }
  // The pump-on rows without r following the pump's own motion: the AGC's
  // chatter is signal there, not noise.
  out.pre_rss = PumpOnFit::rss_without_feedthrough(pre, out.r);
  return out;
}

void PumpEdgeCheck::finish_edge() {
  in_edge_ = false;
  const LineAt post = line_at(post_, cfg_.edge_offset_rows);
  const double n = static_cast<double>(cfg_.fit_rows);
  const Reading line = read(pre_line_, post);
  Reading chosen = line;
  const PumpOnFit::Result* pre = &pre_line_;
  if (pre_bend_.parameters == 3) {
    const Reading bend = read(pre_bend_, post);
    const double f = (line.pre_rss - bend.pre_rss) / 4.0 / (bend.pre_rss / (4.0 * (n - 3.0)));
    if (bend.p2 > 0.0 && f > kBendF * cfg_.row_noise_correlation) {
      chosen = bend;
      pre = &pre_bend_;
    }
  }
  const double p2 = chosen.p2;
  if (!(p2 > 0.0)) return;
  const std::array<double, 4>& r = chosen.r;
  // Noise per quadrature, both fits pooled, and of one part of r: the fits'
  // variance factors count independent rows, the demodulator's rows are not.
  const double dof = 4.0 * (2.0 * n - 2.0 - static_cast<double>(pre->parameters));
  const double var_q = (chosen.pre_rss + post.rss) / dof;
  const double var_r =
      cfg_.row_noise_correlation * var_q * (pre->var_factor + post.var_factor) / p2;
  if (!(var_r > 0.0)) return;
  const double w = 1.0 / var_r;
  weight_ += w;
  for (std::size_t c = 0; c < 4; ++c) {
    weighted_r_[c] += w * r[c];
    weighted_rr_[c] += w * r[c] * r[c];
  }
  max_pump_v_ = std::max(max_pump_v_, std::sqrt(p2));
  ++status_.edges;
  decide();
}

double PumpEdgeCheck::scatter() const {
  if (status_.edges < 2) return 0.0;
  // sum_i w_i (r_i - r_mean)^2 = sum w r^2 - W r_mean^2, per part; over the
  // 4 (edges - 1) degrees of freedom it is the variance of unit weight, and
  // times 1/W that of the mean.
  double chi2 = 0.0;
  for (std::size_t c = 0; c < 4; ++c) {
    const double mean = weighted_r_[c] / weight_;
    chi2 += std::max(0.0, weighted_rr_[c] - weight_ * mean * mean);
  }
  const double dof = 4.0 * static_cast<double>(status_.edges - 1);
  return std::sqrt(chi2 / dof / weight_);
}

void PumpEdgeCheck::decide() {
  PumpEdgeStatus& s = status_;
  s.x_re = weighted_r_[0] / weight_;
  s.x_im = weighted_r_[1] / weight_;
  s.y_re = weighted_r_[2] / weight_;
  s.y_im = weighted_r_[3] / weight_;
  s.sigma_v_per_v = 1.0 / std::sqrt(weight_);
  s.scatter_v_per_v = scatter();
  // The step acts at whatever pump the loop applies: judged at the largest
  // seen, not at the last edge's (an edge where the AGC's pump was near zero
  // would scale a whole feedthrough down to nothing).
  const double v0 = max_pump_v_;
  s.step_v = std::max(std::hypot(s.x_re, s.x_im), std::hypot(s.y_re, s.y_im)) * v0;
  s.step_sigma_v = s.sigma_v_per_v * v0;
  s.tolerance_v = 2.0 * amplitude_v_ * std::sin(cfg_.max_readout_step_rad);
  const double margin = cfg_.n_sigma * s.step_sigma_v;
  if (s.step_v - margin > s.tolerance_v) {
    s.verdict = PumpEdgeVerdict::step;
  } else if (s.step_v + margin <= s.tolerance_v) {
    s.verdict = PumpEdgeVerdict::consistent;
  } else {
    s.verdict = PumpEdgeVerdict::unknown;
  }
}

void PumpEdgeCheck::add_row(const ChainRecord& r, bool pump_on, bool steady) {
  const uint32_t centre = centre_phase(r.nco_phase);
  if (!since_set_) {
    since_s_ = r.t_s;
    since_set_ = true;
  }
  status_.in_force_s = r.t_s - since_s_;
  if (pump_on && !steady) {
    in_edge_ = false;
    was_on_ = false;
    on_rows_ = 0;
    return;
  }
  if (pump_on) {
    // A pump-on row inside an edge: the off stretch was too short to fit.
    in_edge_ = false;
    ring_[ring_pos_] = quadratures(r);
    ring_phase_[ring_pos_] = centre;
    ring_pos_ = (ring_pos_ + 1) % kMaxFitRows;
    if (on_rows_ < kMaxFitRows) ++on_rows_;
    // The pump this row saw: its amplitude over the demodulator's window, at
    // the phase the chain gives it against the NCO (turned into parts at the edge).
    ring_pump_[(ring_pos_ + kMaxFitRows - 1) % kMaxFitRows] = {r.pump_seen_v, r.pump_phase_rad};
    was_on_ = true;
    last_amplitude_v_ = r.wave.a_A_v;
    return;
  }
  if (was_on_ && on_rows_ >= cfg_.fit_rows) begin_edge();
  was_on_ = false;
  on_rows_ = 0;
  if (!in_edge_) return;
  ++off_rows_;
  if (off_rows_ < cfg_.drive_free_rows) return;
  const auto t = static_cast<double>(off_rows_);
  post_.add(t, in_frame(quadratures(r), centre, t));
  if (post_.n >= static_cast<double>(cfg_.fit_rows)) finish_edge();
}

}  // namespace hrg::fw
