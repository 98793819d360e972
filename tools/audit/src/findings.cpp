// SPDX-License-Identifier: MIT
// The selected effects weighed against the misfit they remove, and the
// ones that carry their weight claimed as findings.
#include "auditor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "report_parts.hpp"

namespace hrg::audit::detail {

namespace {

// The share of the misfit an effect removes, weighed where its evidence
// lies: each group's misfit in the proportion of the chi^2 the effect
// removes there; and whether most of that evidence lies where structure is
// left.
struct Share {
  double fraction = 0.0;
  bool where_left = false;
};

Share share_where_evidence_lies(const Chosen& c, const GroupMisfit& gm) {
  double pos = 0.0, in_left = 0.0;
  for (std::size_t g = 0; g < 4; ++g) {
    const double r = std::max(0.0, c.removed_groups[g]);
    pos += r;
    if (gm.left[g]) in_left += r;
  }
  Share s;
  if (!(pos > 0.0)) return s;
  double den = 0.0;
  for (std::size_t g = 0; g < 4; ++g)
    den += std::max(0.0, c.removed_groups[g]) / pos * gm.excess[g];
  s.fraction = c.removed_chi2 / std::max(1.0, den);
  s.where_left = in_left >= 0.5 * pos;
  return s;
}

// The rule weigh_findings() applies, in words, with the run's thresholds.
std::string acceptance_rule_text(const AuditOptions& o) {
  char rule[1280];
  std::snprintf(rule, sizeof rule,
                "a finding stands at least %.3g of its standard deviations from zero and removes "
                "at least %.3g of the baseline's misfit beyond the noise (explains_fraction) "
                "when structure is left (a description or residual variance above %.3g x the "
                "noise; structure left on the excitation segments alone: when most of its "
                "evidence lies in a group of their observations, frequency, balance or angle "
                "drift, above %.3g x its noise, of the misfit where its evidence lies), and "
                "always, of the whole misfit, when it is seen only on the excitation segments "
                "(gap_harmonics) beside an accepted effect on the readout (the pickoff map, "
                "drive feedthrough); the free decays' noise is what the final model leaves there "
                "unless structure is left on them; drive feedthrough, seen on the switching "
                "edges, is not claimed with structure left",
                o.min_significance, o.min_explains_fraction, o.unexplained_ratio,
                o.unexplained_ratio);
  return rule;
}

}  // namespace

GroupMisfit Auditor::group_misfit(const State& full, bool structure_left,
                                  double excess_free) const {
  GroupMisfit gm;
  const auto n = group_counts();
  const auto base = group_chi2(baseline_res_), fin = group_chi2(full.res);
  gm.left[0] = structure_left;
  gm.excess[0] = excess_free;
  for (std::size_t g = 1; g < 4; ++g) {
    gm.left[g] =
        n[g] >= static_cast<double>(kBalanceMinSegments) && fin[g] > opt_.unexplained_ratio * n[g];
    gm.excess[g] = std::max(0.0, base[g] - (gm.left[g] ? n[g] : fin[g]));
  }
  return gm;
}

// A finding must carry its own weight: after drop_unneeded() it must stand
// min_significance of its standard deviations away from zero and remove at
// least min_explains_fraction of the baseline's misfit beyond the noise
// (given everything else) when structure is left (a description or residual
// variance above the noise on the free decays) and, for an effect seen only
// on the excitation segments beside an effect on the readout, always. With
// structure left on the excitation segments alone (a pull no catalogue term
// holds), the rule holds an effect whose evidence lies mostly in an
// excitation group left above its noise, weighed against the misfit where
// its evidence lies. On the averaged model's telemetry the excitation
// segments' pattern-angle drift stays at 15x its noise in every recording,
// the null's included: weighed against the whole misfit, single effects at
// 2-3x threshold and the weaker effects of pairs and triples that act on
// the free decays and the segments' frequency were alternatives. Otherwise
// it is an alternative.
void Auditor::weigh_findings(const State& full, const FeedStat& ft, std::vector<Chosen>& chosen,
                             bool structure_left, AuditResult& out) {
  // The baseline's misfit beyond the noise, on the free decays and on the
  // excitation segments. Where the free decays leave no structure, their
  // noise is what the final model leaves there (the structure test took it
  // for noise): counted against the residual count, a white level 0.5 % low
  // (second differences of the samples) is a misfit of 200 on 40000 block
  // residuals, more than an effect at twice its threshold removes.
  const double free_noise = structure_left ? n_free_res() : free_chi2(full);
  const double excess_free = std::max(1.0, baseline_free_chi2_ - free_noise);
  const double excess_forced =
      std::max(0.0, (baseline_chi2_ - baseline_free_chi2_) - (baseline_n_ - n_free_res()));
  const double excess0 = excess_free + excess_forced;
  const GroupMisfit gm = group_misfit(full, structure_left, excess_free);
  const bool forced_left = gm.left[1] || gm.left[2] || gm.left[3];
  out.acceptance_rule = acceptance_rule_text(opt_);
  if (std::getenv("HRG_AUDIT_DEBUG")) {
    const auto b = group_chi2(baseline_res_), f = group_chi2(full.res), n = group_counts();
    std::fprintf(stderr,
                 "groups baseline/final (count): free %.1f/%.1f (%.0f) freq %.1f/%.1f (%.0f) "
                 "balance %.1f/%.1f (%.0f) angle %.1f/%.1f (%.0f)\n",
                 b[0], f[0], n[0], b[1], f[1], n[1], b[2], f[2], n[2], b[3], f[3], n[3]);
  }
  const bool readout_accepted = std::any_of(
      chosen.begin(), chosen.end(), [](const Chosen& c) { return acts_on_readout(c.effect); });
  std::vector<Chosen> kept;
  for (auto& c : chosen) {
    const int pi = param_of(c.effect);
    const bool whole_misfit = seen_only_on_excitation(c.effect) && readout_accepted;
    const char* why = nullptr;
    double value = std::max(ft.c_x, ft.c_y), sigma = ft.sigma;
    if (pi >= 0) {
      value = effect_value(c.effect, full.fit.p);
      sigma = effect_sigma(c.effect, full.fit.sigma);
      if (!opt_.ar_whitening) {
        sigma /= std::sqrt(full.kappa);
      } else if (c.unique_dchi >= 0.0) {
        // The likelihood-ratio sigma under the whitened noise: |value| over
        // the square root of the chi^2 the effect removes given the rest.
        sigma = std::max(sigma, std::abs(value) / std::sqrt(std::max(c.unique_dchi, 1e-12)));
      }
      if (!c.unique_checked) c.removed_chi2 = std::max(0.0, c.dchi);
      c.fraction = c.removed_chi2 / excess0;
    } else {
      c.fraction = -1.0;  // the edge statistic is outside the free-decay misfit
    }
    // With structure left on the excitation segments alone, an effect is
    // held to its share only where its evidence lies mostly in a group left
    // above its noise, and weighed against the misfit where it lies.
    bool held_to_share = structure_left;
    if (pi >= 0 && !structure_left) {
      held_to_share = forced_left;
      if (c.unique_checked && !whole_misfit) {
        const Share sh = share_where_evidence_lies(c, gm);
        c.fraction = sh.fraction;
        held_to_share = sh.where_left;
      }
    }
    const bool small = pi >= 0 && c.fraction < opt_.min_explains_fraction;
    if (std::getenv("HRG_AUDIT_DEBUG")) {
      std::fprintf(stderr,
                   "weigh %s: value %.4g sigma %.3g dbic %.1f unique_dchi %.1f removed_chi2 %.1f "
                   "excess0 %.1f (baseline chi2 %.1f n %.0f, free chi2 %.1f n %.0f) fraction "
                   "%.3f forced_ratio %.2f structure_left %d held_to_share %d\n",
                   effect_info(c.effect).id, value, sigma, c.dbic, c.unique_dchi, c.removed_chi2,
                   excess0, baseline_chi2_, baseline_n_, baseline_free_chi2_, n_free_res(),
                   c.fraction, forced_ratio(full), structure_left ? 1 : 0, held_to_share ? 1 : 0);
    }
    if (!(std::abs(value) >= opt_.min_significance * sigma)) {
      why = "not significantly away from zero";
    } else if ((structure_left && pi < 0) || (small && held_to_share)) {
      why = "takes up only part of structure that stays unexplained; not claimed";
    } else if (small && whole_misfit) {
      why =
          "seen only on the excitation segments beside an effect on the readout, and removes "
          "less than its share of the misfit; not claimed";
    }
    if (why != nullptr) {
      out.alternatives.push_back({c.effect, value, c.dbic, why});
      continue;
    }
    c.value = value, c.sigma = sigma;
    kept.push_back(c);
  }
  chosen.swap(kept);
}

// The findings that carried their weight, strongest first.
void Auditor::claim_findings(const State& cur, const std::vector<Chosen>& chosen,
                             AuditResult& out) {
  for (const auto& c : chosen) {
    Finding f;
    f.effect = c.effect;
    f.delta_bic = c.dbic;
    f.value = c.value;
    f.sigma = c.sigma;
    f.significance = c.sigma > 0.0 ? std::abs(c.value) / c.sigma : 0.0;
    f.explains_fraction = c.fraction;
    if (c.effect == Effect::drive_feedthrough)
      f.feedthrough_re_im = feedthrough_stat(d_, cur.fit.p, ln_neff(cur)).c_re_im;
    if (c.effect == Effect::gap_harmonics) {
      // The components with the finding's sigma shared in their own proportion.
      const double k = c.sigma / std::max(effect_sigma(c.effect, cur.fit.sigma), 1e-300);
      f.gap_eps_pq_sigma = {cur.fit.p[kGapP], cur.fit.p[kGapQ], k * cur.fit.sigma[kGapP],
                            k * cur.fit.sigma[kGapQ]};
    }
    f.heldout_rms_before_v = out.heldout_rms_v;
    f.heldout_rms_after_v = out.heldout_rms_final_v;
    f.impact = impact_text(d_, cur.fit.p, c.effect, f.value);
    out.findings.push_back(f);
  }
  std::sort(out.findings.begin(), out.findings.end(),
            [](const Finding& a, const Finding& b) { return a.delta_bic > b.delta_bic; });
}

}  // namespace hrg::audit::detail
