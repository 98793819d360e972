// SPDX-License-Identifier: MIT
#include <estimator/window_accumulator.hpp>

#include <cmath>
#include <numbers>

namespace hrg::est {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;

int bin_of_4theta(double four_theta_rad) {
  double a = std::fmod(four_theta_rad, kTwoPi);
  if (a < 0) a += kTwoPi;
  const int bin = static_cast<int>(a / kTwoPi * kCoverageBins);
  return bin >= kCoverageBins ? kCoverageBins - 1 : bin;
}
}  // namespace

int coverage_bin(double theta_A_rad) { return bin_of_4theta(4.0 * theta_A_rad); }

Status WindowAccumulator::begin_window(double t_switch_s) {
  if (open_) return Status::in_window;
  open_ = true;
  have_first_ = false;
  t_switch_s_ = t_switch_s;
  FE_.setZero();
  FQ_.setZero();
  zE_block_.setZero();
  zQ_block_.setZero();
  E_block_ = c4_block_ = s4_block_ = 0;
  in_block_ = 0;
  SE_.setZero();
  SQ_.setZero();
  sE_.setZero();
  sQ_.setZero();
  E_sum_ = c4_sum_ = s4_sum_ = 0;
  blocks_ = 0;
  settling_rejected_ = 0;
  coverage_s_.fill(0);
  return Status::ok;
}

Status WindowAccumulator::add_sample(const WaveSample& s) {
  if (!open_) return Status::not_in_window;
  if (!std::isfinite(s.t_s) || !std::isfinite(s.a_A_v) || !std::isfinite(s.a_B_v) ||
      !std::isfinite(s.theta_A_rad) || !std::isfinite(s.E_v2) || !(s.a_A_v > 0) || !(s.E_v2 > 0) ||
      !(s.damping_scale > 0) || !std::isfinite(s.damping_scale)) {
    open_ = false;
    return Status::bad_sample;
  }
  if (s.t_s < t_switch_s_ + config_.settle_s) {
    ++settling_rejected_;
    return Status::settling;
  }
  const double c4 = std::cos(4.0 * s.theta_A_rad);
  const double s4 = std::sin(4.0 * s.theta_A_rad);
  const double P = s.a_A_v * s.a_A_v - s.a_B_v * s.a_B_v;
  const double u = s.a_A_v * s.a_B_v;
  // Integrands of F_E (columns nu, dnu_C, dnu_S) and F_Q (nu, dw_C, dw_S);
  // the damping columns carry the known scale of the damping at this sample.
  const double k = s.damping_scale;
  const Eigen::Vector3d hE(-k * s.E_v2, -k * P * c4, -k * P * s4);
  const Eigen::Vector3d hQ(-2.0 * k * u, P * s4, -P * c4);
  if (!have_first_) {
    have_first_ = true;
    t_first_s_ = t_prev_s_ = t_block_start_s_ = s.t_s;
    E_ref_ = s.E_v2;
    u_ref_ = u;
  } else {
    const double dt = s.t_s - t_prev_s_;
    if (!(dt > 0)) return Status::time_not_increasing;
    if (dt > config_.max_sample_gap_s) {
      open_ = false;
      return Status::gap;
    }
    FE_ += 0.5 * dt * (hE_prev_ + hE);
    FQ_ += 0.5 * dt * (hQ_prev_ + hQ);
    t_prev_s_ = s.t_s;
  }
  hE_prev_ = hE;
  hQ_prev_ = hQ;
  zE_block_ += Row4(FE_(0), FE_(1), FE_(2), 0.5 * (s.E_v2 - E_ref_));
  zQ_block_ += Row4(FQ_(0), FQ_(1), FQ_(2), u - u_ref_);
  E_block_ += s.E_v2;
  c4_block_ += c4;
  s4_block_ += s4;
  if (++in_block_ == config_.block_samples) close_block();
  return Status::ok;
}

void WindowAccumulator::close_block() {
  const double inv = 1.0 / in_block_;
  const Row4 zE = zE_block_ * inv;
  const Row4 zQ = zQ_block_ * inv;
  SE_.selfadjointView<Eigen::Upper>().rankUpdate(zE);
  SQ_.selfadjointView<Eigen::Upper>().rankUpdate(zQ);
  sE_ += zE;
  sQ_ += zQ;
  E_sum_ += E_block_ * inv;
  const double c4 = c4_block_ * inv;
  const double s4 = s4_block_ * inv;
  c4_sum_ += c4;
  s4_sum_ += s4;
  coverage_s_[bin_of_4theta(std::atan2(s4, c4))] += t_prev_s_ - t_block_start_s_;
  t_block_start_s_ = t_prev_s_;
  ++blocks_;
  zE_block_.setZero();
  zQ_block_.setZero();
  E_block_ = c4_block_ = s4_block_ = 0;
  in_block_ = 0;
}

Status WindowAccumulator::end_window(WindowContribution& out) {
  if (!open_) return Status::not_in_window;
  open_ = false;
  // A partial last block is dropped: its mean would sit at another time step.
  if (blocks_ < config_.min_blocks) return Status::too_short;
  const double n = blocks_;
  // Centering removes the per-window intercepts E(t0)/2 and a_A a_B(t0).
  Sum4 CE = SE_.selfadjointView<Eigen::Upper>();
  Sum4 CQ = SQ_.selfadjointView<Eigen::Upper>();
  CE.noalias() -= sE_ * sE_.transpose() / n;
  CQ.noalias() -= sQ_ * sQ_.transpose() / n;
  const double mean_E = E_sum_ / n;
  // Rows are block means (noise variance sigma^2 a^2 / B); scaling by B / mean E
  // gives every row the per-sample amplitude noise variance sigma^2.
  const double w = config_.block_samples / mean_E;
  // Scatter: E row uses parameters {nu, dnu_C, dnu_S} and y; Q row {nu, dw_C, dw_S} and y.
  constexpr int kE[4] = {kNu, kDnuC, kDnuS, kParams};
  constexpr int kQ[4] = {kNu, kDwC, kDwS, kParams};
  out.info.setZero();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      out.info(kE[i], kE[j]) += w * CE(i, j);
      out.info(kQ[i], kQ[j]) += w * CQ(i, j);
    }
  }
  out.rows = 2.0 * n;
  out.intercepts = 2.0;
  out.t_end_s = t_prev_s_;
  out.duration_s = t_prev_s_ - t_first_s_;
  out.mean_E_v2 = mean_E;
  out.mean_theta_rad = 0.25 * std::atan2(s4_sum_, c4_sum_);
  out.coverage_s = coverage_s_;
  return Status::ok;
}

}  // namespace hrg::est
