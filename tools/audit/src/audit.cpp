// SPDX-License-Identifier: MIT
#include "audit/audit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

#include "audit/plots.hpp"
#include "dataset.hpp"
#include "dsp/wave_variables.hpp"
#include "fit.hpp"
#include "model.hpp"
#include "report_parts.hpp"
#include "selection.hpp"

namespace hrg::audit {

namespace {

using namespace detail;
constexpr double kPi = std::numbers::pi;
constexpr double kRadToDeg = 180.0 / kPi;
// Detection threshold of an effect: the strength that stands this many
// standard deviations of its own estimate above zero (and never below the
// strength at which its delta BIC turns positive).
constexpr double kDetectionSigmas = 5.0;

// Model parameter of each effect (-1: the edge statistic instead).
int param_of(Effect e) {
  static constexpr int kMap[kEffectCount] = {kGain, kPhase, kMis, kDuff, kNld, kTf, kTd, kEs, -1};
  return kMap[static_cast<int>(e)];
}

// Internal parameter -> catalogue unit.
double to_catalogue(Effect e, double v) {
  if (e == Effect::pickoff_phase_mismatch || e == Effect::pickoff_misalignment) {
    return v * kRadToDeg;
  }
  return v;
}

struct State {
  Mask mask{};
  FitResult fit;
  std::vector<double> res;
  double kappa = 1.0;
  bool feedthrough = false;
};

class Auditor {
 public:
  Auditor(const recording::Recording& rec, const AuditOptions& opt)
      : opt_(opt), d_(build_dataset(rec, opt.max_blocks)) {}

  AuditResult run(PlotData* plot);

 private:
  double n_free_res() const { return 4.0 * static_cast<double>(n_blocks_fit_); }
  bool testable(Effect e) const;
  State fit_state(const Mask& mask, const Params& start, bool feedthrough);
  double ln_neff(const State& s) const {
    return std::log(std::max(10.0, s.kappa * static_cast<double>(s.fit.n_res)));
  }
  double delta_bic(const State& cur, const State& next, int extra) const {
    const double kappa = std::min(cur.kappa, next.kappa);
    double dchi = kappa * (cur.fit.chi2 - next.fit.chi2);
    return dchi - extra * ln_neff(next);
  }
  double heldout_rms(const Mask& mask, const Params& start);

  AuditOptions opt_;
  Dataset d_;
  EvalOptions eo_;
  std::size_t n_blocks_fit_ = 0;
};

bool Auditor::testable(Effect e) const {
  switch (e) {
    case Effect::thermal_frequency:
    case Effect::thermal_damping: return d_.has_temp && d_.temp_span_c > 0.02;
    case Effect::electrostatic_spring:
      return d_.has_pump && d_.forced.size() >= 3 && eo_.use_forced;
    case Effect::drive_feedthrough: return d_.edges.size() >= 3;
    default: return true;
  }
}

State Auditor::fit_state(const Mask& mask, const Params& start, bool feedthrough) {
  State s;
  s.mask = mask;
  s.feedthrough = feedthrough;
  s.fit = fit(d_, start, mask, eo_);
  evaluate(d_, s.fit.p, eo_, s.res);
  s.kappa = effective_fraction(s.res, static_cast<std::size_t>(n_free_res()));
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

AuditResult Auditor::run(PlotData* plot) {
  AuditResult out;
  out.notes = d_.notes;
  for (const auto& s : d_.free)
    n_blocks_fit_ += s.n_blocks;
  // Start values: decay rate from the energy of each free segment.
  Params p0{};
  {
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
  }
  Mask base{};
  for (int i : {kDw0, kNu, kDnuC, kDnuS, kDwC, kDwS})
    base[static_cast<std::size_t>(i)] = true;
  double precession = 0.0;
  for (const auto& s : d_.free) {
    precession += std::abs(d_.blocks[s.first_block].rate_rad_s) * (s.t1_s - s.t0_s);
  }
  if (precession * d_.angular_gain > 1.0) base[kK] = base[kCor] = true;

  // Baseline on the free decays alone, then the excitation-segment frequencies
  // join with their scatter as weight.
  State cur = fit_state(base, p0, false);
  {
    // Noise correlated over a few samples makes the block means noisier than
    // the white level from second differences of the samples says. Measure the
    // block noise from second differences of the baseline's block residuals
    // (slow structure cancels there, noise does not) and use the larger.
    // Stride m between the blocks of the difference: grows while the noise
    // is still correlated (modest growth); slow structure would grow ~m^4
    // and stops the search.
    auto second_diff_var = [&](std::size_t m) {
      double acc = 0.0, cnt = 0.0;
      std::size_t k0 = 0;
      for (const auto& seg : d_.free) {
        for (std::size_t b = 2 * m; b < seg.n_blocks; ++b) {
          const std::size_t k = k0 + 4 * b;
          for (std::size_t c = 0; c < 4; ++c) {
            const double d2 =
                cur.res[k + c] - 2.0 * cur.res[k - 4 * m + c] + cur.res[k - 8 * m + c];
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
    if (lambda > 1.2) {
      const double f = std::sqrt(lambda);
      d_.noise_v *= f;
      for (auto& fs : d_.forced)
        fs.se_rad_s *= f;
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "noise is correlated over samples: block noise %.2f x the white level of the "
                    "samples, used as the noise",
                    f);
      out.notes.push_back(buf);
      cur = fit_state(base, cur.fit.p, false);
    }
  }
  if (d_.forced.size() >= 3) {
    // Weight of each excitation segment: its white-noise error and the
    // scatter the baseline leaves beyond it. The scatter is measured after
    // taking out what the frequency-shifting candidates could explain (pump
    // voltage squared, amplitude squared, temperature), so that the signature
    // of an effect is not counted as noise; with few segments only the pump
    // term is taken out.
    const auto fr = forced_residuals(d_, cur.fit.p);
    const std::size_t n = fr.size();
    const int p = n >= 8 ? 3 : 1;
    Eigen::MatrixXd h(static_cast<Eigen::Index>(n), p);
    Eigen::VectorXd y(static_cast<Eigen::Index>(n));
    double se2 = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto& f = d_.forced[i];
      const auto r = static_cast<Eigen::Index>(i);
      h(r, 0) = f.mean_v2;
      if (p == 3) h(r, 1) = f.mean_a2, h(r, 2) = f.mean_temp_c - d_.temp_ref_c;
      y(r) = fr[i];
      se2 += f.se_rad_s * f.se_rad_s / static_cast<double>(n);
    }
    const Eigen::VectorXd coef = h.colPivHouseholderQr().solve(y);
    const double rss = (y - h * coef).squaredNorm();
    const double extra2 = std::max(
        0.0,
        rss / static_cast<double>(std::max<std::size_t>(1, n - static_cast<std::size_t>(p))) - se2);
    for (auto& f : d_.forced)
      f.sigma_rad_s = std::sqrt(f.se_rad_s * f.se_rad_s + extra2);
    eo_.use_forced = true;
    cur = fit_state(base, cur.fit.p, false);
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
  const State baseline = cur;
  out.noise_v = d_.noise_v;
  out.temp_ref_c = d_.temp_ref_c;
  out.free_segments = static_cast<int>(d_.free.size());
  out.forced_segments = static_cast<int>(d_.forced.size());
  out.blocks = static_cast<int>(d_.blocks.size());
  out.samples_per_block = d_.samples_per_block;
  for (const auto& s : d_.free)
    out.heldout_segments += s.heldout ? 1 : 0;

  // Forward selection.
  std::vector<Effect> chosen;
  std::vector<double> chosen_dbic, chosen_dchi;
  FeedStat ft;
  bool first_step = true;
  while (chosen.size() < 4) {
    struct Cand {
      Effect e;
      State s;
      double dbic;
      double value, sigma;
    };
    std::vector<Cand> cands;
    for (const auto& info : effect_table()) {
      const Effect e = info.effect;
      if (std::find(chosen.begin(), chosen.end(), e) != chosen.end()) continue;
      const bool ok = testable(e);
      if (!ok) {
        if (first_step) out.candidates.push_back({e, false, 0.0, 0.0, 0.0, 0.0});
        continue;
      }
      if (e == Effect::drive_feedthrough) {
        // Tested at the end, against the final free-decay model: edge jumps
        // are only evidence once the decays themselves are fitted.
        if (first_step) {
          ft = feedthrough_stat(d_, cur.fit.p, ln_neff(cur));
          out.candidates.push_back({e, true, std::max(ft.c_x, ft.c_y), ft.sigma,
                                    ft.dchi2 - 4.0 * ln_neff(cur),
                                    std::max(ft.threshold, kDetectionSigmas * ft.sigma)});
        }
        continue;
      }
      Mask m = cur.mask;
      const auto pi = static_cast<std::size_t>(param_of(e));
      m[pi] = true;
      State s = fit_state(m, cur.fit.p, cur.feedthrough);
      const double dbic = delta_bic(cur, s, 1);
      cands.push_back({e, s, dbic, to_catalogue(e, s.fit.p[pi]),
                       to_catalogue(e, s.fit.sigma[pi]) / std::sqrt(s.kappa)});
      if (first_step) {
        const double sig = std::abs(to_catalogue(e, s.fit.sigma[pi])) / std::sqrt(s.kappa);
        out.candidates.push_back({e, true, to_catalogue(e, s.fit.p[pi]), sig, dbic,
                                  sig * std::max(kDetectionSigmas, std::sqrt(ln_neff(s)))});
      }
    }
    first_step = false;
    std::sort(cands.begin(), cands.end(),
              [](const Cand& a, const Cand& b) { return a.dbic > b.dbic; });
    if (cands.empty() || cands[0].dbic < opt_.min_delta_bic) {
      for (const auto& c : cands) {
        if (c.dbic > 0.0) {
          out.alternatives.push_back(
              {c.e, c.value, c.dbic, "some evidence, below the acceptance level"});
        }
      }
      break;
    }
    const Cand& win = cands[0];
    // Runner-up close to the winner: re-test it given the winner.
    if (cands.size() > 1 && cands[1].dbic > opt_.min_delta_bic &&
        win.dbic - cands[1].dbic < opt_.ambiguity_bic) {
      const Cand& ru = cands[1];
      bool both = false;
      {
        Mask m = win.s.mask;
        m[static_cast<std::size_t>(param_of(ru.e))] = true;
        const State s2 = fit_state(m, win.s.fit.p, false);
        both = delta_bic(win.s, s2, 1) > opt_.min_delta_bic;
      }
      if (!both) {
        out.alternatives.push_back({ru.e, ru.value, ru.dbic,
                                    "explains the same mismatch almost as well; not needed once "
                                    "the first is in"});
        out.ambiguity_experiment = std::string(effect_info(win.e).id) + " vs " +
                                   effect_info(ru.e).id + ": " +
                                   effect_info(win.e).separating_experiment;
      }
    }
    chosen.push_back(win.e);
    chosen_dbic.push_back(win.dbic);
    chosen_dchi.push_back(cur.fit.chi2 - win.s.fit.chi2);
    cur = win.s;
  }

  // Drive feedthrough against the final model.
  ft = feedthrough_stat(d_, cur.fit.p, ln_neff(cur));
  if (testable(Effect::drive_feedthrough)) {
    const double dbic = ft.dchi2 - 4.0 * ln_neff(cur);
    if (dbic >= opt_.min_delta_bic) {
      chosen.push_back(Effect::drive_feedthrough);
      chosen_dbic.push_back(dbic);
      chosen_dchi.push_back(ft.dchi2);
    } else if (dbic > 0.0) {
      out.alternatives.push_back({Effect::drive_feedthrough, std::max(ft.c_x, ft.c_y), dbic,
                                  "some evidence, below the acceptance level"});
    }
  }

  // Final numbers.
  out.baseline.angular_gain = baseline.fit.p[kK];
  const Params& pb = baseline.fit.p;
  out.baseline.f_hz = d_.f_ref_hz + (d_.carrier_rad_s + pb[kDw0]) / (2.0 * kPi);
  out.baseline.nu_per_s = pb[kNu];
  out.baseline.dmu = std::hypot(pb[kDnuC], pb[kDnuS]) / pb[kNu];
  out.baseline.theta_mu_deg = std::atan2(pb[kDnuS], pb[kDnuC]) / 4.0 * kRadToDeg;
  out.baseline.split_hz = std::hypot(pb[kDwC], pb[kDwS]) / kPi;
  out.baseline.theta_w_deg = std::atan2(pb[kDwS], pb[kDwC]) / 4.0 * kRadToDeg;
  out.baseline.q = kPi * out.baseline.f_hz / pb[kNu];
  out.n_effective = cur.kappa * static_cast<double>(cur.fit.n_res);
  auto rms_v = [&](const State& s) {
    double acc = 0.0;
    const auto n = static_cast<std::size_t>(n_free_res());
    for (std::size_t i = 0; i < n && i < s.res.size(); ++i)
      acc += s.res[i] * s.res[i];
    return std::sqrt(acc / std::max(1.0, n_free_res())) * d_.noise_v;
  };
  out.fit_rms_before_v = rms_v(baseline);
  out.fit_rms_after_v = rms_v(cur);
  out.heldout_rms_v = heldout_rms(baseline.mask, baseline.fit.p);
  out.heldout_rms_final_v = chosen.empty() ? out.heldout_rms_v : heldout_rms(cur.mask, cur.fit.p);
  // With structure left that no candidate takes up, a candidate that only
  // nibbles at it is not a finding: only effects that explain a real share of
  // the baseline's misfit are claimed, the rest are listed as alternatives.
  const double ratio = cur.fit.chi2 / std::max(1.0, static_cast<double>(cur.fit.n_res));
  const bool structure_left = ratio > opt_.unexplained_ratio;
  const double excess0 = baseline.fit.chi2 - static_cast<double>(baseline.fit.n_res);
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    if (structure_left &&
        (chosen[i] == Effect::drive_feedthrough || chosen_dchi[i] < 0.2 * std::max(excess0, 1.0))) {
      const auto pi = param_of(chosen[i]);
      const double v = pi < 0 ? std::max(ft.c_x, ft.c_y)
                              : to_catalogue(chosen[i], cur.fit.p[static_cast<std::size_t>(pi)]);
      out.alternatives.push_back({chosen[i], v, chosen_dbic[i],
                                  "takes up only part of structure that stays unexplained; "
                                  "not claimed"});
      continue;
    }
    Finding f;
    f.effect = chosen[i];
    f.delta_bic = chosen_dbic[i];
    if (chosen[i] == Effect::drive_feedthrough) {
      ft = feedthrough_stat(d_, cur.fit.p, ln_neff(cur));
      f.value = std::max(ft.c_x, ft.c_y);
      f.sigma = ft.sigma;
      f.feedthrough_re_im = ft.c_re_im;
    } else {
      const auto pi = static_cast<std::size_t>(param_of(chosen[i]));
      f.value = to_catalogue(chosen[i], cur.fit.p[pi]);
      f.sigma = to_catalogue(chosen[i], cur.fit.sigma[pi]) / std::sqrt(cur.kappa);
    }
    f.heldout_rms_before_v = out.heldout_rms_v;
    f.heldout_rms_after_v = out.heldout_rms_final_v;
    f.impact = impact_text(d_, cur.fit.p, chosen[i], f.value);
    out.findings.push_back(f);
  }
  out.locations = locate(d_, baseline.fit.p, baseline.res, eo_.use_forced, ft);
  add_candidate_locations(d_, out);
  std::sort(out.locations.begin(), out.locations.end(),
            [](const Location& a, const Location& b) { return a.score > b.score; });
  if (out.locations.size() > 8) out.locations.resize(8);

  std::sort(out.findings.begin(), out.findings.end(),
            [](const Finding& a, const Finding& b) { return a.delta_bic > b.delta_bic; });
  // Structure left after the selected model.
  if (structure_left) {
    const auto left = locate(d_, cur.fit.p, cur.res, eo_.use_forced,
                             feedthrough_stat(d_, cur.fit.p, ln_neff(cur)));
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "residual variance %.2f x the white-noise level after the best model", ratio);
    out.unexplained_note = buf;
    if (!left.empty())
      out.unexplained_note += "; largest at " + left.front().signal + ", " + left.front().where;
    out.verdict = "unexplained";
  } else if (chosen.empty()) {
    out.verdict = "consistent";
  } else if (!out.ambiguity_experiment.empty()) {
    out.verdict = "ambiguous";
  } else {
    out.verdict = "explained";
  }
  if (plot) fill_plot(d_, eo_, baseline.fit.p, cur.fit.p, *plot);
  return out;
}

}  // namespace

AuditResult run_audit(const recording::Recording& rec, const AuditOptions& opt, PlotData* plot) {
  Auditor a(rec, opt);
  return a.run(plot);
}

}  // namespace hrg::audit
