// SPDX-License-Identifier: MIT
// The noise and the weights of the audit's observations: the block noise,
// the excitation segments' frequency, balance and angle-drift weights, and
// the slow (coloured) noise factor of the structure test.
#include "auditor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <Eigen/Dense>

namespace hrg::audit::detail {

namespace {

// Floor of the amplitude balance's scatter, relative to the mean damping nu
// (Auditor::weight_balance).
constexpr double kBalanceFloor = 1e-4;
// Floor of the pattern-angle drift's scatter (Auditor::weight_angle), rad.
constexpr double kAngleFloor = 1e-6;
// Largest |a_A'/a_A| of a segment in the balance, relative to nu. Held
// (kBalanceHeld): the amplitude control holds the wave at its set point;
// these alone when there are enough of them. Recovering from a window
// (0.15-0.25 nu on the default run) the firmware's pump phase is still
// settling and its efficiency c is 7 % lower than held (PumpGain's c1 takes
// that up, less well: on the default run's gap row the file then gives 1.26
// deg/h against 0.94 from the held segments alone); the held among them then
// have a gain of their own (PumpGain::c_settled); beyond kBalanceHold the
// wave rings up with the pump saturated, never used.
constexpr double kBalanceHeld = 0.05;
constexpr double kBalanceHold = 0.5;

}  // namespace

// Shapes forced_scatter takes out of n segments: the pump's V^2 alone with
// few; from 8 also amplitude squared and temperature; for the feedthrough's
// pull test, from 12 also a pickoff phase mismatch's two (it turns the
// measured phase with the pattern angle; in the segments' weights too
// (tried) they lowered the firmware designs' thresholds of a thermal
// frequency and lost a pair of `audit-bench --seed 2026` at the new values).
int forced_shapes(std::size_t n, bool phase_shapes) {
  return phase_shapes && n >= 12 ? 5 : n >= 8 ? 3 : 1;
}

// Variance of the block residuals at long lags over the white level: half
// the mean square of their first differences at stride m within segments,
// for m doubling up to 64 blocks while it grows by less than 2x per doubling.
// White noise stays at 1, 1/f-like noise grows slowly (about logarithmically),
// and a smooth structure grows 4x per doubling and stops the search, so it
// is not taken for noise.
double Auditor::slow_noise_factor(const State& s) const {
  auto half_d = [&](std::size_t m) {
    double acc = 0.0, cnt = 0.0;
    std::size_t k0 = 0;
    for (const auto& seg : d_.free) {
      for (std::size_t b = m; b < seg.n_blocks; ++b) {
        const std::size_t k = k0 + 4 * b;
        for (std::size_t c = 0; c < 4; ++c) {
          const double d1 = s.res[k + c] - s.res[k - 4 * m + c];
          acc += d1 * d1, cnt += 2.0;
        }
      }
      k0 += 4 * seg.n_blocks;
    }
    return cnt > 100.0 ? acc / cnt : -1.0;
  };
  double level = std::max(1.0, half_d(1));
  for (std::size_t m = 2; m <= 64; m *= 2) {
    const double next = half_d(m);
    if (next < 0.0 || next > 2.0 * level) break;
    level = std::max(level, next);
  }
  return level;
}

// Noise correlated over a few samples makes the block means noisier than the
// white level from second differences of the samples says. Measure the block
// noise from second differences of the baseline's block residuals (slow
// structure cancels there, noise does not) and use the larger. Stride m
// between the blocks of the difference: grows while the noise is still
// correlated (modest growth); slow structure would grow ~m^4 and stops the
// search.
State Auditor::adopt_block_noise(const Mask& base, State cur, AuditResult& out) {
  auto second_diff_var = [&](std::size_t m) {
    double acc = 0.0, cnt = 0.0;
    std::size_t k0 = 0;
    for (const auto& seg : d_.free) {
      for (std::size_t b = 2 * m; b < seg.n_blocks; ++b) {
        const std::size_t k = k0 + 4 * b;
        for (std::size_t c = 0; c < 4; ++c) {
          const double d2 = cur.res[k + c] - 2.0 * cur.res[k - 4 * m + c] + cur.res[k - 8 * m + c];
          acc += d2 * d2, cnt += 6.0;
        }
      }
      k0 += 4 * seg.n_blocks;
    }
    return cnt > 0.0 ? acc / cnt : 1.0;
  };
  double lambda = second_diff_var(1);
  for (std::size_t m = 2; m <= 8; m *= 2) {
    const double next = second_diff_var(m);
    if (next > 4.0 * lambda) break;
    lambda = std::max(lambda, next);
  }
  if (lambda <= 1.2) return cur;
  const double f = std::sqrt(lambda);
  d_.noise_v *= f;
  for (auto& fs : d_.forced) {
    fs.se_rad_s *= f;
    fs.balance_se_per_s *= f;
  }
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "noise is correlated over samples: block noise %.2f x the white level of the "
                "samples, used as the noise",
                f);
  out.notes.push_back(buf);
  return fit_state(base, cur.fit.p, false);
}

// Weight of each excitation segment: its white-noise error and the scatter
// the baseline leaves beyond it. The scatter is measured after taking out
// what the frequency-shifting candidates could explain (pump voltage squared,
// amplitude squared, temperature), so that the signature of an effect is not
// counted as noise; with few segments only the pump term is taken out.
State Auditor::weight_forced_segments(const Mask& base, State cur, AuditResult& out) {
  start_balance_ = cur.fit.p;
  forced_extra2_ = forced_extra2(cur.fit.p);
  for (auto& f : d_.forced)
    f.sigma_rad_s = std::sqrt(f.se_rad_s * f.se_rad_s + forced_extra2_);
  weight_balance(out);
  eo_.use_forced = true;
  return fit_state(base, cur.fit.p, false);
}

// Scatter of the excitation segments' frequencies beyond their white noise
// that the model `p` leaves, once the shapes of forced_scatter are out.
double Auditor::forced_extra2(const Params& p) const {
  const auto fr = forced_residuals(d_, p);
  const std::size_t n = fr.size();
  const int k = forced_shapes(n, false);
  double se2 = 0.0;
  for (const auto& f : d_.forced)
    se2 += f.se_rad_s * f.se_rad_s / static_cast<double>(n);
  const double rss = forced_scatter(fr, k, p[kNu]);
  return std::max(
      0.0,
      rss / static_cast<double>(std::max<std::size_t>(1, n - static_cast<std::size_t>(k))) - se2);
}

// The excitation segments' frequency weights measured again against the
// model the selection chose (the description in), that model refitted with
// them, and the baseline's residuals counted with them for the findings'
// shares. Their scatter beyond the white noise was measured against the
// baseline, which leaves in it what the selection then finds: a pickoff
// phase mismatch or misalignment turns the segments' measured phase with
// the pattern angle. On the triple of design 1 of `audit-bench --seed 2026`
// (a phase mismatch of -0.0078 deg beside a spring and a Duffing term,
// telemetry) that scatter was 1.03e-5 rad/s against the baseline and 3.4e-6
// against the selected model, whose frequencies then stood at chi^2 18.8 on
// 44 segments: the Duffing term, weighed against loose segments, fell below
// 5 sigma. The selection and the detection thresholds keep the baseline's
// weights (a null's model is its baseline); weights only tighten.
State Auditor::reweight_forced_segments(const State& baseline, State full) {
  if (!eo_.use_forced || d_.forced.size() < 3) return full;
  const double extra2 = forced_extra2(full.fit.p);
  if (std::getenv("HRG_AUDIT_DEBUG"))
    std::fprintf(stderr, "reweight: extra %.3g -> %.3g rad/s\n", std::sqrt(forced_extra2_),
                 std::sqrt(extra2));
  if (!(extra2 < forced_extra2_)) return full;
  forced_extra2_ = extra2;
  for (auto& f : d_.forced)
    f.sigma_rad_s = std::sqrt(f.se_rad_s * f.se_rad_s + extra2);
  evaluate(d_, baseline.fit.p, eo_, baseline_res_);
  baseline_chi2_ = 0.0;
  for (double r : baseline_res_)
    baseline_chi2_ += r * r;
  return fit_state(full.mask, full.fit.p, full.feedthrough);
}

// Sum of squares the excitation segments' frequency residuals `fr` leave
// once what the candidates that move them could explain is taken out (the
// first p of: pump voltage squared, amplitude squared, temperature, and a
// pickoff phase mismatch's readout and pump pull). The phase mismatch phi
// shows the phase of a standing vibration at about -phi sin^2 2theta, so the
// frequency by phi/2 (cos 4theta1 - cos 4theta0) / T, and the pump that
// follows it pulls by (a_A'/a_A + nu) phi (1 - cos 4theta) weighted by V^2
// (pickoff_pump_pull, model.cpp). Counted as noise in the feedthrough's
// pull test, a phase mismatch of 0.0022 deg on telemetry (design 7 of
// `audit-bench --seed 2026`) left the scatter after the pull 1.67x the
// noise (1.5x allowed), the pull was left in the segments, and a spring of
// -1.62e-8 Hz/V^2 beside them was -1.37e-8 at delta BIC 2.6, no finding.
double Auditor::forced_scatter(const std::vector<double>& fr, int p, double nu_per_s) const {
  const std::size_t n = fr.size();
  Eigen::MatrixXd h(static_cast<Eigen::Index>(n), p);
  Eigen::VectorXd y(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const auto& f = d_.forced[i];
    const auto r = static_cast<Eigen::Index>(i);
    h(r, 0) = f.mean_v2;
    if (p >= 3) h(r, 1) = f.mean_a2, h(r, 2) = f.mean_temp_c - d_.temp_ref_c;
    if (p == 5) {
      h(r, 3) = f.end_change([](double th0, double th1) {
        return std::cos(4.0 * th1) - std::cos(4.0 * th0);
      }) / (f.t1_s - f.t0_s);
      h(r, 4) = f.mean_v2 > 0.0 ? (f.dlna_per_s + nu_per_s) * (1.0 - f.mean_v2c4 / f.mean_v2) : 0.0;
    }
    y(r) = fr[i];
  }
  const Eigen::VectorXd coef = h.colPivHouseholderQr().solve(y);
  return (y - h * coef).squaredNorm();
}

// Weight of each segment's amplitude balance (model.hpp): its white-noise
// error and the scatter the baseline leaves beyond it once the shapes the
// pump can have are taken out (c V^2 and the gap's c V^2 cos/sin 4 theta), so
// that a gap harmonic is not counted as noise. That scatter comes from the
// ends of a segment (the amplitude loop's state when the window cuts it), so
// it is taken as e / T per segment of length T, e from the fit weighted by T;
// e has a floor of kBalanceFloor nu x 1 s. Only segments where the amplitude
// control holds the wave (|a_A'/a_A| <= kBalanceHeld nu) when there are
// kBalanceMinSegments of them, else those that recover (<= kBalanceHold nu).
void Auditor::weight_balance(AuditResult& out) {
  if (!d_.has_pump) return;
  const double nu = start_balance_[kNu];
  auto segments_within = [&](double hold) {
    std::vector<std::size_t> use;
    for (std::size_t i = 0; i < d_.forced.size(); ++i) {
      const auto& f = d_.forced[i];
      if (f.mean_v2 > 0.0 && std::abs(f.dlna_per_s) <= hold * nu) use.push_back(i);
    }
    return use;
  };
  std::vector<std::size_t> use = segments_within(kBalanceHeld);
  if (use.size() < kBalanceMinSegments) {
    // The few held among the recovering: their pump has settled (PumpGain).
    for (std::size_t i : use)
      d_.forced[i].pump_settled = true;
    use = segments_within(kBalanceHold);
  }
  const std::size_t n = use.size();
  if (n < kBalanceMinSegments) return;
  if (ft_shown_) remove_balance_pull(use, out);
  double se2 = 0.0;
  const double rss = balance_scatter(use, se2);
  const double floor = kBalanceFloor * nu * 1.0;
  const bool any_settled =
      std::any_of(use.begin(), use.end(), [&](std::size_t i) { return d_.forced[i].pump_settled; });
  const double dof = static_cast<double>(n - (any_settled ? 5 : 4));
  const double e2 = std::max(floor * floor, rss / dof - se2);
  if (std::getenv("HRG_AUDIT_DEBUG")) {
    const std::vector<double> left = balance_left(d_, start_balance_);
    std::fprintf(stderr, "balance: %zu segments, e %.3g (floor %.3g), se2 %.3g\n", n, std::sqrt(e2),
                 floor, se2);
    for (std::size_t i : use) {
      const auto& f = d_.forced[i];
      std::fprintf(stderr, "  %.2f-%.2f dlna %.3g L/v2 %.5g c4 %.2f s4 %.2f\n", f.t0_s, f.t1_s,
                   f.dlna_per_s, left[i] / f.mean_v2, f.mean_c4, f.mean_s4);
    }
  }
  for (std::size_t i : use) {
    auto& f = d_.forced[i];
    const double t = f.t1_s - f.t0_s;
    f.balance_sigma_per_s = std::sqrt(f.balance_se_per_s * f.balance_se_per_s + e2 / (t * t));
  }
  weight_angle(use);
}

// Sum of squares the amplitude balance of segments `use` leaves, weighted by
// T, once the pump's shapes are fitted (weight_balance); `se2` gets the white
// noise's share of it per segment.
double Auditor::balance_scatter(const std::vector<std::size_t>& use, double& se2) const {
  const std::size_t n = use.size();
  const std::vector<double> left = balance_left(d_, start_balance_);
  Eigen::MatrixXd h(static_cast<Eigen::Index>(n), 5);
  Eigen::VectorXd y(static_cast<Eigen::Index>(n));
  se2 = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& f = d_.forced[use[k]];
    const auto r = static_cast<Eigen::Index>(k);
    const double t = f.t1_s - f.t0_s;
    const double settled = f.pump_settled ? 1.0 : 0.0;
    h(r, 0) = t * f.mean_v2 * (1.0 - settled), h(r, 4) = t * f.mean_v2 * settled;
    h(r, 1) = t * f.mean_v2c4, h(r, 2) = t * f.mean_v2s4;
    h(r, 3) = t * true_growth_per_s(f, start_balance_) * f.mean_v2 * (1.0 - settled);
    y(r) = t * left[use[k]];
    se2 += t * t * f.balance_se_per_s * f.balance_se_per_s / static_cast<double>(n);
  }
  const Eigen::VectorXd coef = h.colPivHouseholderQr().solve(y);
  return (y - h * coef).squaredNorm();
}

// Weight of the pattern-angle drift of the same segments, the same way: the
// scatter beyond the white noise once the gap's shapes (c V^2 cos/sin 4
// theta), an error of K (the rate over the span) and the shapes a pickoff
// gain or misalignment leaves beside the baseline are taken out (before, on
// the firmware's telemetry a gain of 3.6e-4 raised e from 1e-6 to 1.5e-5 rad
// and hid itself: found 2.57e-4 +- 5.6e-5, not a finding), as e / T over the
// end rows' span T, e from the fit weighted by T, with a floor of
// kAngleFloor rad. No segment weighs more than one of the median length
// (e / min(T, T_median)): e / T alone gave one long segment of the
// firmware's telemetry (14 s, a drift no model term holds) 17x its weight,
// and its pull on the baseline a false gain mismatch.
void Auditor::weight_angle(const std::vector<std::size_t>& use) {
  for (std::size_t i : use)
    d_.forced[i].angle_sigma_rad_s = 1.0;  // marks the segments angle_residuals() takes
  const std::vector<double> r = angle_residuals(d_, start_balance_);
  const std::size_t n = use.size();
  Eigen::MatrixXd h(static_cast<Eigen::Index>(n), 7);
  Eigen::VectorXd y(static_cast<Eigen::Index>(n));
  std::vector<double> spans;
  double se2 = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& f = d_.forced[use[k]];
    const auto row = static_cast<Eigen::Index>(k);
    const double t = f.angle_span_s;
    h(row, 0) = t * f.mean_v2c4, h(row, 1) = t * f.mean_v2s4, h(row, 2) = t * f.angle_rate_rad_s;
    // A pickoff gain g (misalignment b) reads the angle as theta + g/4 sin
    // 4theta (+ b/2 cos 4theta); free decays at one pattern rate r0 cannot
    // tell that from a damping anisotropy dnu_S = -2 g r0 (dnu_C = -4 b r0),
    // so the baseline takes it up, and its drift then acts on every segment,
    // a still one too. These shapes are fitted as the gap's are, so that what
    // a pickoff candidate explains is not counted as noise.
    h(row, 3) = t * f.mean_c4, h(row, 4) = t * f.mean_s4;
    h(row, 5) = std::sin(4.0 * f.theta1_rad) - std::sin(4.0 * f.theta0_rad);
    h(row, 6) = std::cos(4.0 * f.theta1_rad) - std::cos(4.0 * f.theta0_rad);
    y(row) = t * r[k];
    se2 += t * t * f.angle_se_rad_s * f.angle_se_rad_s / static_cast<double>(n);
    spans.push_back(t);
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(h);
  const Eigen::VectorXd coef = qr.solve(y);
  const double rss = (y - h * coef).squaredNorm();
  const auto dof = static_cast<double>(n) - static_cast<double>(qr.rank());
  const double e2 = std::max(kAngleFloor * kAngleFloor, rss / std::max(1.0, dof) - se2);
  auto mid = spans.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(spans.begin(), mid, spans.end());
  const double t_median = *mid;
  if (std::getenv("HRG_AUDIT_DEBUG"))
    std::fprintf(stderr, "angle: e %.3g rad, se2 %.3g, median span %.3g s\n", std::sqrt(e2), se2,
                 t_median);
  for (std::size_t k = 0; k < n; ++k) {
    auto& f = d_.forced[use[k]];
    const double t = std::min(f.angle_span_s, t_median);
    f.angle_sigma_rad_s = std::sqrt(f.angle_se_rad_s * f.angle_se_rad_s + e2 / (t * t));
    if (std::getenv("HRG_AUDIT_DEBUG"))
      std::fprintf(stderr, "  %.2f-%.2f angle res %.3g sigma %.3g pull %.3g c4 %.2f s4 %.2f\n",
                   f.t0_s, f.t1_s, r[k], f.angle_sigma_rad_s, f.angle_pull_rad_s, f.mean_c4,
                   f.mean_s4);
  }
}

}  // namespace hrg::audit::detail
