// SPDX-License-Identifier: MIT
// The audit's report of the data, the baseline and the locations of its
// misfit, and the verdict.
#include "auditor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "report_parts.hpp"

namespace hrg::audit::detail {

void Auditor::describe_data(AuditResult& out) const {
  out.noise_v = d_.noise_v;
  out.temp_ref_c = d_.temp_ref_c;
  out.free_segments = static_cast<int>(d_.free.size());
  out.forced_segments = static_cast<int>(d_.forced.size());
  out.forced_segments_left_out = static_cast<int>(d_.forced_jittery);
  out.blocks = static_cast<int>(d_.blocks.size());
  out.samples_per_block = d_.samples_per_block;
  for (const auto& s : d_.free)
    out.heldout_segments += s.heldout ? 1 : 0;
}

void Auditor::report_baseline(const State& baseline, const State& cur, bool any_chosen,
                              AuditResult& out) {
  const Params& pb = baseline.fit.p;
  out.baseline.angular_gain = pb[kK];
  out.baseline.f_hz = d_.f_ref_hz + (d_.carrier_rad_s + pb[kDw0]) / (2.0 * kPi);
  out.baseline.nu_per_s = pb[kNu];
  out.baseline.dmu = std::hypot(pb[kDnuC], pb[kDnuS]) / pb[kNu];
  out.baseline.theta_mu_deg = std::atan2(pb[kDnuS], pb[kDnuC]) / 4.0 * kRadToDeg;
  out.baseline.split_hz = std::hypot(pb[kDwC], pb[kDwS]) / kPi;
  out.baseline.theta_w_deg = std::atan2(pb[kDwS], pb[kDwC]) / 4.0 * kRadToDeg;
  out.baseline.q = kPi * out.baseline.f_hz / pb[kNu];
  out.n_effective = cur.kappa * static_cast<double>(cur.fit.n_res);
  out.fit_rms_before_v = rms_v(baseline);
  out.fit_rms_after_v = rms_v(cur);
  out.heldout_rms_v = heldout_rms(baseline.mask, baseline.fit.p);
  out.heldout_rms_final_v = any_chosen ? heldout_rms(cur.mask, cur.fit.p) : out.heldout_rms_v;
}

// Where the baseline misfits (strongest eight), and where each candidate sees
// it; `ft` is the switching-edge statistic against the selected model.
void Auditor::report_locations(const State& baseline, const FeedStat& ft, AuditResult& out) {
  out.locations = locate(d_, baseline.fit.p, baseline.res, eo_.use_forced, ft);
  if (eo_.use_forced && !d_.forced.empty()) {
    const ForcedOffset o = forced_offset(d_, baseline.fit.p);
    out.excitation_offset_hz = o.mean_rad_s / (2.0 * kPi);
    out.excitation_offset_sigma_hz = o.sigma_rad_s / (2.0 * kPi);
    out.excitation_mean_pump_v2 = o.mean_v2;
  }
  add_candidate_locations(d_, out);
  std::sort(out.locations.begin(), out.locations.end(),
            [](const Location& a, const Location& b) { return a.score > b.score; });
  if (out.locations.size() > 8) out.locations.resize(8);
}

void Auditor::set_verdict(const State& cur, const FeedStat& ft, bool structure_left,
                          AuditResult& out) {
  if (!out.description.terms.empty()) {
    out.unexplained_note = "structure the catalogue cannot name, described as: ";
    for (std::size_t i = 0; i < out.description.terms.size(); ++i)
      out.unexplained_note += (i ? "; " : "") + out.description.terms[i].text;
    out.verdict = "unexplained";
  } else if (structure_left) {
    const double ratio =
        cur.fit.chi2 / std::max(1.0, static_cast<double>(cur.fit.n_res)) / slow_noise_factor(cur);
    const auto left = locate(d_, cur.fit.p, cur.res, eo_.use_forced, ft);
    char buf[200];
    std::snprintf(buf, sizeof buf, "residual variance %.2f x the noise level after the best model",
                  ratio);
    out.unexplained_note = buf;
    if (!left.empty())
      out.unexplained_note += "; largest at " + left.front().signal + ", " + left.front().where;
    out.verdict = "unexplained";
  } else if (out.findings.empty()) {
    out.verdict = confounded_ ? "ambiguous" : "consistent";
  } else if (!out.ambiguity_experiment.empty()) {
    out.verdict = "ambiguous";
  } else {
    out.verdict = "explained";
  }
}

}  // namespace hrg::audit::detail
