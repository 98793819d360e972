// SPDX-License-Identifier: MIT
// Checks of the selected effects: each still needed beside the others, a
// pickoff effect constant over the recording, a thermal effect told apart
// from a drift in time.
#include "auditor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace hrg::audit::detail {

// Backward elimination over the chosen catalogue effects: each is refitted
// out of the model (every other accepted effect and the description in); the
// weakest whose delta BIC there is below the acceptance level leaves it (an
// alternative: what it explained, the others explain as well) and the model
// is refitted without it, until every remaining one is needed. One at a time,
// so that two effects that can stand for each other do not both leave.
State Auditor::drop_unneeded(State full, std::vector<Chosen>& chosen, AuditResult& out) {
  if (!opt_.ar_whitening && chosen.size() < 2 && out.description.terms.empty()) return full;
  for (;;) {
    std::size_t worst = chosen.size();
    double worst_dbic = 1e300;
    State worst_without;
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      const Effect e = chosen[k].effect;
      if (param_of(e) < 0) continue;
      State without =
          fit_state(with_effect(full.mask, e, false), without_effect(full.fit.p, e), false);
      // Seen on the excitation segments alone, an effect is counted beside
      // the slow noise those see: what an offset or a drift of the
      // demodulated signals explains as well is not its evidence.
      double slow = 0.0;
      if (seen_only_on_excitation(e)) {
        slow = std::max(0.0, slow_offset_chi2(d_, without.res) - slow_offset_chi2(d_, full.res));
        if (std::getenv("HRG_AUDIT_DEBUG"))
          std::fprintf(stderr, "drop-one %s: %.1f of its chi^2 an offset explains as well\n",
                       effect_info(e).id, slow);
      }
      chosen[k].unique_dchi = delta_chi2(without, full) - slow;
      const double unique_dbic = chosen[k].unique_dchi - n_params_of(e) * ln_neff(full);
      chosen[k].removed_chi2 = std::max(0.0, without.fit.chi2 - full.fit.chi2);
      const auto chi_without = group_chi2(without.res), chi_full = group_chi2(full.res);
      for (std::size_t g = 0; g < 4; ++g)
        chosen[k].removed_groups[g] = chi_without[g] - chi_full[g];
      chosen[k].unique_checked = true;
      if (std::getenv("HRG_AUDIT_DEBUG"))
        std::fprintf(stderr,
                     "drop-one %s: unique dbic %.1f removes free %.1f freq %.1f balance %.1f "
                     "angle %.1f\n",
                     effect_info(e).id, unique_dbic, chosen[k].removed_groups[0],
                     chosen[k].removed_groups[1], chosen[k].removed_groups[2],
                     chosen[k].removed_groups[3]);
      if (unique_dbic < worst_dbic)
        worst_dbic = unique_dbic, worst = k, worst_without = std::move(without);
    }
    if (worst == chosen.size() || worst_dbic >= opt_.min_delta_bic) return full;
    const Chosen& c = chosen[worst];
    out.alternatives.push_back(
        {c.effect, effect_value(c.effect, full.fit.p), c.dbic,
         "not needed once the other accepted effects and the description are in"});
    chosen.erase(chosen.begin() + static_cast<std::ptrdiff_t>(worst));
    full = std::move(worst_without);
  }
}

// A catalogue effect is a constant of the gyro: a pickoff gain or phase
// mismatch that changes in time (or with the temperature) over the
// recording is not one, and a calibration with its mean would not hold.
// Each accepted pickoff effect is tested against its own parameter varying
// in time and with the temperature (the generic terms that say so, on top
// of everything accepted); when that variation earns the description's
// evidence, the effect is no finding and the variation joins the
// description.
State Auditor::test_constancy(State full, std::vector<Chosen>& chosen, AuditResult& out) {
  static constexpr struct {
    Effect e;
    const char* term;
  } kVarying[] = {{Effect::pickoff_gain_mismatch, "gain_ratio_drift"},
                  {Effect::pickoff_gain_mismatch, "gain_ratio_vs_temperature"},
                  {Effect::pickoff_phase_mismatch, "phase_drift"}};
  bool changed = false;
  for (const auto& v : kVarying) {
    const auto it = std::find_if(chosen.begin(), chosen.end(),
                                 [&](const Chosen& c) { return c.effect == v.e; });
    if (it == chosen.end()) continue;
    const GenericTerm* t = term_of(v.term);
    if (t == nullptr || full.mask[static_cast<std::size_t>(t->param_ids[0])]) continue;
    if (t->needs_temp && !(d_.has_temp && d_.temp_span_c > 0.02)) continue;
    State s = fit_state(with_term(full.mask, *t), full.fit.p, full.feedthrough);
    const double dbic = delta_bic(full, s, t->n_params);
    if (dbic < opt_.min_description_bic) continue;
    // Material: the change over the recording is at least a fifth of the
    // constant (a tiny trend under a large mismatch leaves the constant good).
    const auto pc = static_cast<std::size_t>(param_of(v.e));
    const auto pv = static_cast<std::size_t>(t->param_ids[0]);
    const double span = t->needs_temp
                            ? d_.temp_span_c
                            : (d_.t_s.empty() ? 0.0 : (d_.t_s.back() - d_.t_s.front()) / 3600.0);
    if (std::abs(s.fit.p[pv]) * span < 0.2 * std::abs(full.fit.p[pc])) continue;
    if (described_.empty()) {
      out.description.fit_rms_before_v = rms_v(full);
      out.description.heldout_rms_before_v = heldout_rms(full.mask, full.fit.p);
    }
    const double excess0 = std::max(1.0, baseline_chi2_ - baseline_n_);
    out.description.terms.push_back({t->id, "", dbic, (full.fit.chi2 - s.fit.chi2) / excess0});
    described_.push_back(t);
    out.alternatives.push_back(
        {it->effect, to_catalogue(it->effect, s.fit.p[pc]), it->dbic,
         std::string("not a constant: its parameter changes (") + t->id +
             "), so a constant calibration would not hold; described instead"});
    chosen.erase(it);
    full = std::move(s);
    changed = true;
  }
  if (changed) finish_description(full, heldout_rms(full.mask, full.fit.p), out);
  return full;
}

// Correlation of the temperature with time over the free-decay blocks.
double Auditor::temp_time_correlation() const {
  double n = 0.0, st = 0.0, sT = 0.0, stt = 0.0, sTT = 0.0, stT = 0.0;
  for (const auto& s : d_.free) {
    for (std::size_t b = 0; b < s.n_blocks; ++b) {
      const Block& bl = d_.blocks[s.first_block + b];
      n += 1.0, st += bl.t_s, sT += bl.temp_c;
      stt += bl.t_s * bl.t_s, sTT += bl.temp_c * bl.temp_c, stT += bl.t_s * bl.temp_c;
    }
  }
  const double vt = stt - st * st / n, vT = sTT - sT * sT / n;
  return vt > 0.0 && vT > 0.0 ? (stT - st * sT / n) / std::sqrt(vt * vT) : 0.0;
}

// A thermal effect is linear in the temperature, a drift linear in time:
// when the temperature follows time over the recording the two predict the
// same, and the recording cannot say which it is (a slow change of the gyro,
// or of its electronics, that is no thermal effect at all). Each accepted
// thermal effect is refitted with the same quantity drifting in time in its
// place (everything else kept); unless the thermal model fits better by the
// acceptance level, it is no finding: an alternative with the reason, and
// the verdict is ambiguous with the experiment that separates them.
void Auditor::test_thermal_vs_drift(const State& full, std::vector<Chosen>& chosen,
                                    AuditResult& out) {
  static constexpr struct {
    Effect e;
    const char* term;
    const char* quantity;
  } kPairs[] = {{Effect::thermal_damping, "damping_drift", "damping"},
                {Effect::thermal_frequency, "frequency_drift", "frequency"}};
  for (const auto& pr : kPairs) {
    const auto it = std::find_if(chosen.begin(), chosen.end(),
                                 [&](const Chosen& c) { return c.effect == pr.e; });
    const GenericTerm* t = term_of(pr.term);
    if (it == chosen.end() || t == nullptr) continue;
    const auto pc = static_cast<std::size_t>(param_of(pr.e));
    const auto pt = static_cast<std::size_t>(t->param_ids[0]);
    if (full.mask[pt]) continue;  // the drift is in the model already
    Mask m = full.mask;
    m[pc] = false, m[pt] = true;
    Params q = full.fit.p;
    q[pc] = 0.0;
    const State swapped = fit_state(m, q, full.feedthrough);
    const double margin = delta_chi2(swapped, full);
    if (margin >= opt_.min_delta_bic) continue;
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "the temperature follows time in this recording (correlation %.3f over the free "
                  "decays): a %s drift in time explains the same (thermal better by chi^2 %.1f "
                  "only), so the two cannot be told apart",
                  temp_time_correlation(), pr.quantity, margin);
    out.alternatives.push_back({pr.e, to_catalogue(pr.e, full.fit.p[pc]), it->dbic, buf});
    if (out.ambiguity_experiment.empty()) {
      out.ambiguity_experiment = std::string(effect_info(pr.e).id) + " vs a " + pr.quantity +
                                 " drift in time: repeat with the temperature swinging "
                                 "independently of time (up and down over the run)";
    }
    confounded_ = true;
    chosen.erase(it);
  }
}

}  // namespace hrg::audit::detail
