// SPDX-License-Identifier: MIT
// The description of what the catalogue model leaves, by the generic terms.
#include "auditor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "description.hpp"

namespace hrg::audit::detail {

// Generic description of what the catalogue model leaves: forward selection
// over the generic terms on top of it (stricter evidence: a search over many
// shapes), refitted by output error with everything else. A term is taken
// only when it also reproduces on the held-out segments (their mean-square
// residual falls by at least a quarter of what it falls on the fitted ones):
// slow coloured noise fits a term on the data it sees, not on the rest) and
// when it is material: it removes at least min_description_share of the
// baseline's free-decay misfit beyond the noise (the excitation segments'
// frequencies follow whatever disturbs their phase, a feedthrough too, and
// stay with the catalogue's spring; a trace of model error under a large
// catalogue effect is not worth a description; a weak structure in a
// recording that is otherwise at the noise is). Its evidence is counted on
// residuals whitened by the AR noise model, so slow coloured noise does not
// earn it; noise slower than that model follows must also be outgrown
// (min_description_fall). Returns the model with the description (the
// catalogue model when nothing is accepted).
State Auditor::describe(const State& cat, AuditResult& out) {
  State cur = cat;
  std::vector<const GenericTerm*> taken;
  const double excess0 = std::max(1.0, baseline_free_chi2_ - n_free_res());
  double heldout_cur = -1.0;
  for (int step = 0; step < opt_.max_description_terms; ++step) {
    const GenericTerm* best = nullptr;
    double best_dbic = -1e300;
    for (const auto& t : generic_terms()) {
      if (std::find(taken.begin(), taken.end(), &t) != taken.end()) continue;
      if (t.needs_temp && !(d_.has_temp && d_.temp_span_c > 0.02)) continue;
      if (t.needs_forced && !eo_.use_forced) continue;
      // Scored after a few iterations (the terms enter nearly linearly).
      const State s = fit_state(with_term(cur.mask, t), cur.fit.p, cur.feedthrough, 2);
      const double dbic = delta_bic(cur, s, t.n_params);
      if (dbic > best_dbic) best_dbic = dbic, best = &t;
    }
    if (std::getenv("HRG_AUDIT_DEBUG") && best != nullptr)
      std::fprintf(stderr, "describe best %s: dbic %.1f\n", best->id, best_dbic);
    if (best == nullptr || best_dbic < opt_.min_description_bic) break;
    State next = fit_state(with_term(cur.mask, *best), cur.fit.p, cur.feedthrough);
    const double dbic = delta_bic(cur, next, best->n_params);
    if (dbic < opt_.min_description_bic) break;
    if (heldout_cur < 0.0) heldout_cur = heldout_rms(cur.mask, cur.fit.p);
    const double heldout_next = heldout_rms(next.mask, next.fit.p);
    const double fitted_fall = rms_v(cur) * rms_v(cur) - rms_v(next) * rms_v(next);
    const double heldout_fall = heldout_cur * heldout_cur - heldout_next * heldout_next;
    if (!(heldout_fall > 0.25 * fitted_fall)) break;
    const double share = (free_chi2(cur) - free_chi2(next)) / excess0;
    if (std::getenv("HRG_AUDIT_DEBUG"))
      std::fprintf(stderr,
                   "describe try %s: dbic %.1f heldout fall %.3g fitted fall %.3g share %.3f "
                   "slow %.2f noise^2 %.3g\n",
                   best->id, dbic, heldout_fall, fitted_fall, share, slow_noise_factor(next),
                   d_.noise_v * d_.noise_v);
    if (share < opt_.min_description_share) break;
    // Noise slower than the AR model follows (variance at long lags above
    // the white level): its slowest octaves are offsets and drifts over a
    // recording, so a term must then also stand above them. That variance is
    // the one the term leaves: measured with the term's own structure still
    // in the residual, it counts that structure as slow noise (an offset of
    // 13x the noise on the x pickoff of the firmware's telemetry raised it
    // from 1.0 to 1.27 and held its own description back).
    const double slow = slow_noise_factor(next);
    if (slow > 1.2 && fitted_fall < opt_.min_description_fall * slow * d_.noise_v * d_.noise_v)
      break;
    if (std::getenv("HRG_AUDIT_DEBUG"))
      std::fprintf(stderr, "describe: %s dbic %.1f share %.3f\n", best->id, dbic, share);
    out.description.terms.push_back({best->id, "", dbic, share});
    taken.push_back(best);
    heldout_cur = heldout_next;
    cur = std::move(next);
  }
  if (taken.empty()) return cat;
  described_ = taken;
  out.description.fit_rms_before_v = rms_v(cat);
  out.description.heldout_rms_before_v = heldout_rms(cat.mask, cat.fit.p);
  finish_description(cur, heldout_cur, out);
  return cur;
}

// The description's words and numbers from the model `cur` that holds it.
void Auditor::finish_description(const State& cur, double heldout_after, AuditResult& out) {
  Params sigma{};
  for (int i = 0; i < kParamCount; ++i) {
    const auto k = static_cast<std::size_t>(i);
    sigma[k] = cur.fit.sigma[k] / std::sqrt(cur.kappa);
  }
  for (std::size_t i = 0; i < described_.size(); ++i)
    out.description.terms[i].text = describe_term(*described_[i], d_, cur.fit.p, sigma);
  out.description.fit_rms_after_v = rms_v(cur);
  out.description.heldout_rms_after_v = heldout_after;
}

}  // namespace hrg::audit::detail
