// SPDX-License-Identifier: MIT
// Forward selection over the catalogue's effects, the runner-up's retest
// and the drive feedthrough on the switching edges.
#include "auditor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace hrg::audit::detail {

namespace {

// Detection threshold of an effect: the strength that stands this many
// standard deviations of its own estimate above zero (and never below the
// strength at which its delta BIC turns positive).
constexpr double kDetectionSigmas = 5.0;
constexpr const char* kSomeEvidence = "some evidence, below the acceptance level";

}  // namespace

// Every effect not yet chosen, added to the current model alone, best first.
// On the first step each one's evidence and detection threshold is recorded.
// Drive feedthrough is tested at the end, against the final free-decay model:
// edge jumps are only evidence once the decays themselves are fitted.
std::vector<Candidate> Auditor::score_candidates(const State& cur,
                                                 const std::vector<Chosen>& chosen, bool first_step,
                                                 AuditResult& out) {
  std::vector<Candidate> cands;
  for (const auto& info : effect_table()) {
    const Effect e = info.effect;
    if (std::any_of(chosen.begin(), chosen.end(), [&](const Chosen& c) { return c.effect == e; }))
      continue;
    if (!testable(e)) {
      if (first_step) out.candidates.push_back({e, false, 0.0, 0.0, 0.0, 0.0});
      continue;
    }
    if (e == Effect::drive_feedthrough) {
      if (first_step) {
        const FeedStat ft = feedthrough_stat(d_, cur.fit.p, ln_neff(cur));
        out.candidates.push_back({e, true, std::max(ft.c_x, ft.c_y), ft.sigma,
                                  ft.dchi2 - 4.0 * ln_neff(cur),
                                  std::max(ft.threshold, kDetectionSigmas * ft.sigma)});
      }
      continue;
    }
    State s = fit_state(with_effect(cur.mask, e), cur.fit.p, cur.feedthrough);
    const double dbic = delta_bic(cur, s, n_params_of(e));
    const double sig = effect_sigma(e, s.fit.sigma) / std::sqrt(s.kappa);
    const double value = effect_value(e, s.fit.p);
    if (first_step) {
      out.candidates.push_back({e, true, value, std::abs(sig), dbic,
                                std::abs(sig) * std::max(kDetectionSigmas, std::sqrt(ln_neff(s)))});
    }
    cands.push_back({e, std::move(s), dbic, value, sig});
  }
  std::sort(cands.begin(), cands.end(),
            [](const Candidate& a, const Candidate& b) { return a.dbic > b.dbic; });
  return cands;
}

// Runner-up close to the winner: re-test it given the winner; when it adds
// nothing the two explain the same mismatch and the verdict is ambiguous.
void Auditor::retest_runner_up(const std::vector<Candidate>& cands, AuditResult& out) {
  if (cands.size() < 2 || cands[1].dbic <= opt_.min_delta_bic ||
      cands[0].dbic - cands[1].dbic >= opt_.ambiguity_bic)
    return;
  const Candidate& win = cands[0];
  const Candidate& ru = cands[1];
  const State s2 = fit_state(with_effect(win.s.mask, ru.e), win.s.fit.p, false);
  if (delta_bic(win.s, s2, n_params_of(ru.e)) > opt_.min_delta_bic) return;
  out.alternatives.push_back({ru.e, ru.value, ru.dbic,
                              "explains the same mismatch almost as well; not needed once "
                              "the first is in"});
  out.ambiguity_experiment = std::string(effect_info(win.e).id) + " vs " + effect_info(ru.e).id +
                             ": " + effect_info(win.e).separating_experiment;
}

// Forward selection refitting everything at each step, from the effects
// already `chosen` on; `cur` ends as the selected model. Up to four catalogue
// effects besides drive feedthrough (tested on the edges).
void Auditor::forward_select(State& cur, std::vector<Chosen>& chosen, AuditResult& out) {
  bool first_step = chosen.empty();
  auto in_model = [&] {
    return std::count_if(chosen.begin(), chosen.end(),
                         [](const Chosen& c) { return c.effect != Effect::drive_feedthrough; });
  };
  while (in_model() < 4) {
    std::vector<Candidate> cands = score_candidates(cur, chosen, first_step, out);
    first_step = false;
    if (std::getenv("HRG_AUDIT_DEBUG")) {
      for (std::size_t k = 0; k < std::min<std::size_t>(4, cands.size()); ++k)
        std::fprintf(stderr, "select step %zu: %s dbic %.1f value %.4g sigma %.3g\n", chosen.size(),
                     effect_info(cands[k].e).id, cands[k].dbic, cands[k].value, cands[k].sigma);
    }
    if (cands.empty() || cands[0].dbic < opt_.min_delta_bic) {
      for (const auto& c : cands) {
        if (c.dbic > 0.0) {
          out.alternatives.push_back({c.e, c.value, c.dbic, kSomeEvidence});
        }
      }
      break;
    }
    retest_runner_up(cands, out);
    chosen.push_back({cands[0].e, cands[0].dbic, cur.fit.chi2 - cands[0].s.fit.chi2});
    cur = std::move(cands[0].s);
  }
}

// Drive feedthrough against the final model.
void Auditor::test_feedthrough(const State& cur, const FeedStat& ft, std::vector<Chosen>& chosen,
                               AuditResult& out) {
  if (!testable(Effect::drive_feedthrough)) return;
  const double dbic = ft.dchi2 - 4.0 * ln_neff(cur);
  if (dbic >= opt_.min_delta_bic) {
    chosen.push_back({Effect::drive_feedthrough, dbic, ft.dchi2});
  } else if (dbic > 0.0) {
    out.alternatives.push_back(
        {Effect::drive_feedthrough, std::max(ft.c_x, ft.c_y), dbic, kSomeEvidence});
  }
}

}  // namespace hrg::audit::detail
