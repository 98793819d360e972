// SPDX-License-Identifier: MIT
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "audit/audit.hpp"

namespace hrg::audit {

namespace {

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string str(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      o += '\\';
      o += c;
    } else if (c == '\n') {
      o += "\\n";
    } else {
      o += c;
    }
  }
  return o + "\"";
}

// A JSON array of the items, each written by `item`, one per line.
template <typename T, typename F>
std::string json_list(const std::vector<T>& items, F item) {
  std::string j = "[";
  for (std::size_t i = 0; i < items.size(); ++i)
    j += std::string(i ? ",\n    " : "\n    ") + item(items[i]);
  return j + (items.empty() ? "]" : "\n  ]");
}

std::string baseline_json(const AuditResult& r) {
  const auto& b = r.baseline;
  return "{\"params\": {\"f_hz\": " + num(b.f_hz) + ", \"q\": " + num(b.q) +
         ", \"nu_per_s\": " + num(b.nu_per_s) + ", \"dmu\": " + num(b.dmu) +
         ", \"theta_mu_deg\": " + num(b.theta_mu_deg) + ", \"split_hz\": " + num(b.split_hz) +
         ", \"theta_w_deg\": " + num(b.theta_w_deg) + ", \"angular_gain\": " + num(b.angular_gain) +
         "}, \"heldout_rms\": " + num(r.heldout_rms_v) +
         ", \"fit_rms\": " + num(r.fit_rms_before_v) + ", \"noise_v\": " + num(r.noise_v) + "}";
}

std::string location_json(const Location& l) {
  return "{\"signal\": " + str(l.signal) + ", \"where\": " + str(l.where) +
         ", \"score\": " + num(l.score) + "}";
}

std::string finding_json(const Finding& f) {
  const auto& info = effect_info(f.effect);
  return "{\"effect\": " + str(info.id) + ", \"explanation\": " + str(info.explanation) +
         ", \"params\": {" + str(info.param) + ": " + num(f.value) + "}, \"uncertainty\": {" +
         str(info.param) + ": " + num(f.sigma) + "}, \"delta_bic\": " + num(f.delta_bic) +
         ", \"heldout_rms_before\": " + num(f.heldout_rms_before_v) +
         ", \"heldout_rms_after\": " + num(f.heldout_rms_after_v) +
         ", \"explains_fraction\": " + num(f.explains_fraction < 0.0 ? NAN : f.explains_fraction) +
         ", \"significance\": " + num(f.significance) + ", \"impact\": " + str(f.impact) + "}";
}

std::string alternative_json(const Alternative& a) {
  const auto& info = effect_info(a.effect);
  return "{\"effect\": " + str(info.id) + ", \"params\": {" + str(info.param) + ": " +
         num(a.value) + "}, \"delta_bic\": " + num(a.delta_bic) + ", \"note\": " + str(a.note) +
         "}";
}

std::string term_json(const DescriptionTerm& t) {
  return "{\"term\": " + str(t.term) + ", \"text\": " + str(t.text) +
         ", \"delta_bic\": " + num(t.delta_bic) +
         ", \"explains_fraction\": " + num(t.explains_fraction) + "}";
}

// The description of what the catalogue cannot name, with the fit before and
// after it (never a catalogue name, never written into a calibration).
std::string description_json(const Description& d) {
  return "{\"terms\": " + json_list(d.terms, term_json) +
         ", \"fit_rms_before\": " + num(d.fit_rms_before_v) +
         ", \"fit_rms_after\": " + num(d.fit_rms_after_v) +
         ", \"heldout_rms_before\": " + num(d.heldout_rms_before_v) +
         ", \"heldout_rms_after\": " + num(d.heldout_rms_after_v) + "}";
}

std::string candidate_json(const CandidateScore& c) {
  return "{\"effect\": " + str(effect_info(c.effect).id) +
         ", \"testable\": " + (c.testable ? "true" : "false") + ", \"value\": " + num(c.value) +
         ", \"sigma\": " + num(c.sigma) + ", \"threshold\": " + num(c.threshold) +
         ", \"delta_bic\": " + num(c.delta_bic) + "}";
}

}  // namespace

std::string to_json(const AuditResult& r) {
  std::string j = "{\n  \"verdict\": " + str(r.verdict) + ",\n";
  j += "  \"baseline\": " + baseline_json(r) + ",\n";
  j += "  \"locations\": " + json_list(r.locations, location_json) + ",\n";
  j += "  \"findings\": " + json_list(r.findings, finding_json) + ",\n";
  j += "  \"alternatives\": " + json_list(r.alternatives, alternative_json);
  if (!r.ambiguity_experiment.empty()) {
    j += ",\n  \"separating_experiment\": " + str(r.ambiguity_experiment);
  }
  if (!r.unexplained_note.empty()) j += ",\n  \"unexplained\": " + str(r.unexplained_note);
  if (!r.description.terms.empty()) j += ",\n  \"description\": " + description_json(r.description);
  j += ",\n  \"acceptance_rule\": " + str(r.acceptance_rule);
  j += ",\n  \"candidates\": " + json_list(r.candidates, candidate_json);
  j += ",\n  \"excitation_segments\": " + std::to_string(r.forced_segments) +
       ",\n  \"excitation_segments_left_out\": " + std::to_string(r.forced_segments_left_out);
  j += ",\n  \"excitation_offset_mhz\": " + num(r.excitation_offset_hz * 1e3) +
       ",\n  \"excitation_offset_sigma_mhz\": " + num(r.excitation_offset_sigma_hz * 1e3) +
       ",\n  \"excitation_mean_pump_v2\": " + num(r.excitation_mean_pump_v2);
  j += ",\n  \"notes\": [";
  for (std::size_t i = 0; i < r.notes.size(); ++i)
    j += (i ? ", " : "") + str(r.notes[i]);
  j += "]\n}\n";
  return j;
}

std::string to_text(const AuditResult& r, const std::string& source) {
  std::string t;
  char buf[512];
  t += "VERDICT: " + r.verdict + "   (" + source + ")\n";
  if (r.findings.empty() && r.verdict == "consistent") {
    t += "  The seed's model explains the recording to the noise level; no left-out physics is "
         "justified.\n";
  } else if (r.findings.empty()) {
    t += "  No effect of the catalogue explains the misfit.\n";
  }
  for (const auto& f : r.findings) {
    const auto& info = effect_info(f.effect);
    std::snprintf(buf, sizeof buf, "  FOUND %s: %s = %.4g +/- %.2g %s (delta BIC %.1f)\n", info.id,
                  info.param, f.value, f.sigma, info.unit, f.delta_bic);
    t += buf;
    if (f.explains_fraction >= 0.0) {
      std::snprintf(buf, sizeof buf,
                    "    weight:  removes %.0f %% of the baseline's misfit beyond the noise, "
                    "%.1f sigma from zero\n",
                    100.0 * f.explains_fraction, f.significance);
      t += buf;
    }
    t += "    physics: " + std::string(info.explanation) + "\n";
    t += "    impact:  " + f.impact + "\n";
  }
  if (!r.ambiguity_experiment.empty()) {
    t += "  AMBIGUOUS: " + r.ambiguity_experiment + "\n";
  }
  for (const auto& a : r.alternatives) {
    std::snprintf(buf, sizeof buf, "  alternative %s: %.4g %s (delta BIC %.1f): %s\n",
                  effect_info(a.effect).id, a.value, effect_info(a.effect).unit, a.delta_bic,
                  a.note.c_str());
    t += buf;
  }
  if (!r.description.terms.empty()) {
    t += "  UNEXPLAINED, described (not a catalogue effect; never a calibration):\n";
    for (const auto& d : r.description.terms)
      t += "    - " + d.text + "\n";
    std::snprintf(buf, sizeof buf,
                  "    fit: %.3g V -> %.3g V; held-out segments %.3g V -> %.3g V (noise %.3g V)\n",
                  r.description.fit_rms_before_v, r.description.fit_rms_after_v,
                  r.description.heldout_rms_before_v, r.description.heldout_rms_after_v, r.noise_v);
    t += buf;
  } else if (!r.unexplained_note.empty()) {
    t += "  UNEXPLAINED: " + r.unexplained_note + "\n";
  }
  t += "\nWhere the baseline misfits:\n";
  if (r.locations.empty()) t += "  nowhere above 5 sigma\n";
  for (const auto& l : r.locations) {
    std::snprintf(buf, sizeof buf, "  [score %.3g] %s: %s\n", l.score, l.signal.c_str(),
                  l.where.c_str());
    t += buf;
  }
  std::snprintf(buf, sizeof buf,
                "\nFit (free-decay rms per sample): baseline %.3g V -> final %.3g V; held-out "
                "segments %.3g V -> %.3g V; noise %.3g V\n",
                r.fit_rms_before_v, r.fit_rms_after_v, r.heldout_rms_v, r.heldout_rms_final_v,
                r.noise_v);
  t += buf;
  const auto& b = r.baseline;
  std::snprintf(buf, sizeof buf,
                "Baseline: f = %.6f Hz, Q = %.4g (nu = %.4g 1/s), dmu = %.3g at %.1f deg, "
                "split = %.3g mHz at %.1f deg, K = %.4g\n",
                b.f_hz, b.q, b.nu_per_s, b.dmu, b.theta_mu_deg, b.split_hz * 1e3, b.theta_w_deg,
                b.angular_gain);
  t += buf;
  std::snprintf(buf, sizeof buf,
                "Data: %d free-decay segments (%d held out), %d excitation segments, %d blocks of "
                "%d samples, effective samples %.0f\n",
                r.free_segments, r.heldout_segments, r.forced_segments, r.blocks,
                r.samples_per_block, r.n_effective);
  t += buf;
  if (r.excitation_offset_sigma_hz > 0.0) {
    std::snprintf(buf, sizeof buf,
                  "Excitation segments against the free decays (baseline): %+.3g +- %.2g mHz at "
                  "mean pump_v^2 %.3g V^2\n",
                  r.excitation_offset_hz * 1e3, r.excitation_offset_sigma_hz * 1e3,
                  r.excitation_mean_pump_v2);
    t += buf;
  }
  for (const auto& n : r.notes)
    t += "note: " + n + "\n";
  return t;
}

}  // namespace hrg::audit
