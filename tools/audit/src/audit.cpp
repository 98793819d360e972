// SPDX-License-Identifier: MIT
// run_audit: the Auditor's fitted states, the baseline, and its steps in
// order (run); the steps themselves are in the files auditor.hpp names.
#include "audit/audit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "auditor.hpp"
#include "report_parts.hpp"

namespace hrg::audit {

namespace detail {

bool Auditor::testable(Effect e) const {
  switch (e) {
    case Effect::thermal_frequency:
    case Effect::thermal_damping: return d_.has_temp && d_.temp_span_c > 0.02;
    case Effect::electrostatic_spring:
      return d_.has_pump && d_.forced.size() >= 3 && eo_.use_forced;
    case Effect::drive_feedthrough: return d_.edges.size() >= 3;
    case Effect::gap_harmonics:
      return d_.has_pump && eo_.use_forced &&
             std::any_of(d_.forced.begin(), d_.forced.end(),
                         [](const ForcedSegment& f) { return f.balance_sigma_per_s > 0.0; });
    default: return true;
  }
}

State Auditor::fit_state(const Mask& mask, const Params& start, bool feedthrough,
                         int max_iterations) {
  State s;
  s.mask = mask;
  s.feedthrough = feedthrough;
  s.fit = fit(d_, start, mask, eo_, max_iterations);
  evaluate(d_, s.fit.p, eo_, s.res);
  s.kappa = effective_fraction(s.res, static_cast<std::size_t>(n_free_res()));
  if (opt_.ar_whitening) s.ar = fit_ar_noise(d_, s.res);
  return s;
}

double Auditor::heldout_rms(const Mask& mask, const Params& start) {
  EvalOptions train = eo_;
  train.include_heldout = false;
  const FitResult f = fit(d_, start, mask, train);
  EvalOptions ho;
  ho.heldout_only = true;
  std::vector<double> r;
  evaluate(d_, f.p, ho, r);
  if (r.empty()) return 0.0;
  double s = 0.0;
  for (double v : r)
    s += v * v;
  // Back from noise units to volts per block sample.
  return std::sqrt(s / static_cast<double>(r.size())) * d_.noise_v;
}

double Auditor::free_chi2(const State& s) const {
  double acc = 0.0;
  const auto n = static_cast<std::size_t>(n_free_res());
  for (std::size_t i = 0; i < n && i < s.res.size(); ++i)
    acc += s.res[i] * s.res[i];
  return acc;
}

double Auditor::forced_ratio(const State& s) const {
  const auto n0 = static_cast<std::size_t>(n_free_res());
  if (s.res.size() < n0 + kBalanceMinSegments) return 0.0;  // too few to tell
  double acc = 0.0;
  for (std::size_t i = n0; i < s.res.size(); ++i)
    acc += s.res[i] * s.res[i];
  return acc / static_cast<double>(s.res.size() - n0);
}

std::array<double, 4> Auditor::group_counts() const {
  std::array<double, 4> n{n_free_res(), static_cast<double>(d_.forced.size()), 0.0, 0.0};
  for (const auto& f : d_.forced) {
    n[2] += f.balance_sigma_per_s > 0.0 ? 1.0 : 0.0;
    n[3] += f.angle_sigma_rad_s > 0.0 ? 1.0 : 0.0;
  }
  if (!eo_.use_forced) n[1] = n[2] = n[3] = 0.0;
  return n;
}

std::array<double, 4> Auditor::group_chi2(const std::vector<double>& res) const {
  const auto n = group_counts();
  std::array<double, 4> chi{};
  std::size_t i = 0;
  for (std::size_t g = 0; g < 4; ++g) {
    const std::size_t end = std::min(res.size(), i + static_cast<std::size_t>(n[g]));
    for (; i < end; ++i)
      chi[g] += res[i] * res[i];
  }
  return chi;
}

double Auditor::rms_v(const State& s) const {
  return std::sqrt(free_chi2(s) / std::max(1.0, n_free_res())) * d_.noise_v;
}

// Start values: decay rate from the energy of each free segment.
Params Auditor::start_params() const {
  Params p0{};
  double num = 0.0, den = 0.0;
  for (const auto& s : d_.free) {
    const Block& a = d_.blocks[s.first_block];
    const Block& b = d_.blocks[s.first_block + s.n_blocks - 1];
    const double ea = std::norm(a.x) + std::norm(a.y), eb = std::norm(b.x) + std::norm(b.y);
    if (ea > 0 && eb > 0 && b.t_s > a.t_s) {
      num += -0.5 * std::log(eb / ea);
      den += b.t_s - a.t_s;
    }
  }
  p0[kNu] = den > 0 ? std::max(num / den, 1e-6) : 1e-3;
  p0[kK] = d_.angular_gain;
  p0[kCor] = 1.0;
  return p0;
}

// The seed's parameters; K (and the second-order Coriolis factor) only when
// the free decays precess far enough to observe it.
Mask Auditor::baseline_mask() const {
  Mask base{};
  for (int i : {kDw0, kNu, kDnuC, kDnuS, kDwC, kDwS})
    base[static_cast<std::size_t>(i)] = true;
  double precession = 0.0;
  for (const auto& s : d_.free) {
    precession += std::abs(d_.blocks[s.first_block].rate_rad_s) * (s.t1_s - s.t0_s);
  }
  if (precession * d_.angular_gain > 1.0) base[kK] = base[kCor] = true;
  return base;
}

// Baseline on the free decays alone, then the excitation-segment frequencies
// join with their scatter as weight.
State Auditor::fit_baseline(AuditResult& out) {
  const Mask base = baseline_mask();
  // Several starts of the damping anisotropy (dmu 0.05 in four directions of
  // 4 th_mu): a baseline caught in a local minimum would be the start of
  // every candidate after it.
  const Params p0 = start_params();
  // The starts are compared after a few iterations; the best is refined.
  State cur = fit_state(base, p0, false, 4);
  for (int k = 0; k < 4; ++k) {
    Params q = p0;
    q[kDnuC] = 0.05 * p0[kNu] * std::cos(0.5 * kPi * k);
    q[kDnuS] = 0.05 * p0[kNu] * std::sin(0.5 * kPi * k);
    State s = fit_state(base, q, false, 4);
    if (s.fit.chi2 < cur.fit.chi2 - 1e-6 * cur.fit.chi2) cur = std::move(s);
  }
  cur = fit_state(base, cur.fit.p, false);
  cur = adopt_block_noise(base, cur, out);
  if (d_.forced.size() >= 3) {
    remove_feedthrough_pull(cur, out);
    cur = weight_forced_segments(base, cur, out);
  }
  if (std::getenv("HRG_AUDIT_DEBUG")) {
    const auto fr = forced_residuals(d_, cur.fit.p);
    for (std::size_t i = 0; i < fr.size(); ++i) {
      const auto& f = d_.forced[i];
      std::fprintf(stderr,
                   "forced %zu t=%.2f-%.2f res=%.3g rad/s sigma=%.3g se=%.3g v2=%.3g T=%.3f\n", i,
                   f.t0_s, f.t1_s, fr[i], f.sigma_rad_s, f.se_rad_s, f.mean_v2, f.mean_temp_c);
    }
    std::fprintf(stderr, "baseline chi2 %.1f n %zu kappa %.3f\n", cur.fit.chi2, cur.fit.n_res,
                 cur.kappa);
  }
  return cur;
}

AuditResult Auditor::run(PlotData* plot) {
  AuditResult out;
  out.notes = d_.notes;
  for (const auto& s : d_.free)
    n_blocks_fit_ += s.n_blocks;
  const State baseline = fit_baseline(out);
  describe_data(out);
  State cur = baseline;
  std::vector<Chosen> chosen;
  forward_select(cur, chosen, out);
  // The switching edges against the final free-decay model.
  const FeedStat ft = feedthrough_stat(d_, cur.fit.p, ln_neff(cur));
  test_feedthrough(cur, ft, chosen, out);
  // The description is always looked for: a weak structure outside the
  // catalogue can leave the total misfit at the noise.
  baseline_chi2_ = baseline.fit.chi2;
  baseline_n_ = static_cast<double>(baseline.fit.n_res);
  baseline_free_chi2_ = free_chi2(baseline);
  baseline_res_ = baseline.res;
  State full = describe(cur, out);
  full = reweight_forced_segments(baseline, std::move(full));
  full = drop_unneeded(std::move(full), chosen, out);
  full = test_constancy(std::move(full), chosen, out);
  test_thermal_vs_drift(full, chosen, out);
  // Structure is left when the description found some, or when the residual
  // stays above the noise including its slow (coloured) part.
  const double ratio = full.fit.chi2 / std::max(1.0, static_cast<double>(full.fit.n_res));
  const double slow = slow_noise_factor(full);
  if (slow > 1.2) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "slow (coloured) noise: the residual's variance at lags of up to 64 blocks is "
                  "%.2f x its white level, used as the noise of the structure test",
                  slow);
    out.notes.push_back(buf);
  }
  const bool structure_left =
      ratio / slow > opt_.unexplained_ratio || !out.description.terms.empty();
  weigh_findings(full, ft, chosen, structure_left, out);
  report_baseline(baseline, full, !chosen.empty() || !out.description.terms.empty(), out);
  claim_findings(full, chosen, out);
  report_locations(baseline, ft, out);
  set_verdict(full, ft, structure_left, out);
  if (std::getenv("HRG_AUDIT_DEBUG"))
    std::fprintf(stderr, "weigh verdict %s\n", out.verdict.c_str());
  if (plot) fill_plot(d_, eo_, baseline.fit.p, full.fit.p, *plot);
  return out;
}

}  // namespace detail

AuditResult run_audit(const recording::Recording& rec, const AuditOptions& opt, PlotData* plot) {
  detail::Auditor a(rec, opt);
  return a.run(plot);
}

}  // namespace hrg::audit
