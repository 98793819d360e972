// SPDX-License-Identifier: MIT
// The benchmark's cases beyond one catalogue effect (a null with coloured
// noise, a pair, a triple, one effect outside the catalogue) and how a case
// is scored against the audit's findings.
#include "bench_cases.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <numbers>
#include <vector>

namespace hrg::audit::bench {

namespace {

constexpr double kPi = std::numbers::pi;

std::string fmt_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Two or three distinct catalogue effects at once, each at 2x-3x its
// threshold; a hit when every one is a finding with its parameter within 20 %.
BenchCase multi_case(const Scenario& base, const AuditResult& null_r, int count, std::mt19937_64& g,
                     const AuditFn& audit, const std::string& save_path) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<const CandidateScore*> pool;
  for (const auto& cand : null_r.candidates) {
    if (cand.testable && cand.threshold > 0.0 && std::isfinite(cand.threshold) &&
        physical(base, cand.effect, 3.0 * cand.threshold))
      pool.push_back(&cand);
  }
  BenchCase c;
  c.kind = count == 2 ? CaseKind::pair : CaseKind::triple;
  if (static_cast<int>(pool.size()) < count) return c;
  std::shuffle(pool.begin(), pool.end(), g);
  Scenario s = base;
  for (int k = 0; k < count; ++k) {
    const auto& cand = *pool[static_cast<std::size_t>(k)];
    double v = (2.0 + u(g)) * cand.threshold * (u(g) < 0.5 ? -1.0 : 1.0);
    if (cand.effect == Effect::drive_feedthrough || cand.effect == Effect::gap_harmonics)
      v = std::abs(v);
    c.truths.push_back(static_cast<int>(cand.effect));
    c.true_values.push_back(v);
    conceal(s, cand.effect, v, g);
  }
  const recording::Recording rec = bench::simulate(s);
  if (!save_path.empty()) recording::write_recording(save_path, rec);
  const auto [r, secs] = audit(rec);
  c.verdict = r.verdict;
  c.seconds = secs;
  c.findings = static_cast<int>(r.findings.size());
  c.all_found = true;
  for (std::size_t k = 0; k < c.truths.size(); ++k) {
    const auto it = std::find_if(r.findings.begin(), r.findings.end(), [&](const Finding& f) {
      return static_cast<int>(f.effect) == c.truths[k];
    });
    c.found_values.push_back(it == r.findings.end() ? std::nan("") : it->value);
    if (it == r.findings.end() ||
        std::abs(it->value - c.true_values[k]) > 0.2 * std::abs(c.true_values[k]))
      c.all_found = false;
  }
  return c;
}

double threshold_of(const AuditResult& r, Effect e) {
  for (const auto& c : r.candidates) {
    if (c.effect == e && c.testable && std::isfinite(c.threshold)) return c.threshold;
  }
  return 0.0;
}

// One effect outside the catalogue, well above what the design can detect: a
// drift of the y/x gain ratio or of the y phase over the recording, or a y
// gain that follows the temperature, changing by 6x-12x the detection
// threshold of the constant pickoff gain (phase) mismatch over the recording
// (the temperature swing), or an offset of 5-20x the noise on the x pickoff.
BenchCase outside_case(const Scenario& base, const AuditResult& null_r, std::mt19937_64& g,
                       const AuditFn& audit) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Scenario s = base;
  s.outside = static_cast<OutsideEffect>(1 + static_cast<int>(u(g) * kOutsideEffectCount));
  const double th = s.outside == OutsideEffect::phase_drift
                        ? threshold_of(null_r, Effect::pickoff_phase_mismatch) * kPi / 180.0
                        : threshold_of(null_r, Effect::pickoff_gain_mismatch);
  const double total = (6.0 + 6.0 * u(g)) * th * (u(g) < 0.5 ? -1.0 : 1.0);
  switch (s.outside) {
    case OutsideEffect::gain_ratio_drift:
    case OutsideEffect::phase_drift: s.outside_value = total / (s.duration_s / 3600.0); break;
    case OutsideEffect::offset_x: s.outside_value = (5.0 + 15.0 * u(g)) * base.noise_v; break;
    case OutsideEffect::gain_ratio_vs_temp:
      s.outside_value = total / (2.0 * base.temp_swing_c);
      break;
    case OutsideEffect::none: break;
  }
  BenchCase c;
  c.kind = CaseKind::outside;
  c.outside = outside_name(s.outside);
  c.true_value = s.outside_value;
  const auto [r, secs] = audit(bench::simulate(s));
  c.verdict = r.verdict;
  c.seconds = secs;
  c.findings = static_cast<int>(r.findings.size());
  c.top = top_of(r, c.top_value);
  const auto& desc = r.description;
  c.heldout_over_noise = desc.terms.empty() ? 0.0 : desc.heldout_rms_after_v / r.noise_v;
  c.described = r.verdict == "unexplained" && !desc.terms.empty() && r.findings.empty() &&
                c.heldout_over_noise <= 1.2;
  c.description_matches = !desc.terms.empty() && desc.terms.front().term == c.outside;
  return c;
}

}  // namespace

[[gnu::format(printf, 1, 2)]] std::string fmt_line(const char* f, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(buf, sizeof buf, f, ap);
  va_end(ap);
  return buf;
}

bool is_hit(const BenchCase& c) {
  return c.top == c.truth && std::abs(c.top_value - c.true_value) <= 0.2 * std::abs(c.true_value);
}

int top_of(const AuditResult& r, double& value) {
  if (r.findings.empty()) return -1;
  value = r.findings.front().value;
  return static_cast<int>(r.findings.front().effect);
}

// The damping may change by at most half over the campaign's amplitude or
// temperature range: beyond that a concealed damping effect is not physical.
bool physical(const Scenario& base, Effect e, double value) {
  const double a_max = 1.3 * base.amplitude_v;
  return !((e == Effect::nonlinear_damping && std::abs(value) * a_max * a_max > 0.5) ||
           (e == Effect::thermal_damping && std::abs(value) * base.temp_swing_c > 0.5));
}

void run_extra_cases(const BenchOptions& o, const Scenario& base, const AuditResult& null_r, int d,
                     uint64_t seed, const AuditFn& audit, std::string* log, BenchResult& res) {
  std::mt19937_64 g(seed ^ 0x5bd1e9955bd1e995ULL);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  {
    Scenario s = base;
    s.flicker_corner_hz = std::exp(std::log(0.3) + u(g) * std::log(10.0));
    const recording::Recording rec = bench::simulate(s);
    if (!o.save_multi_dir.empty())
      recording::write_recording(
          o.save_multi_dir + "/design" + std::to_string(d) + "_coloured.csv.gz", rec);
    const auto [r, secs] = audit(rec);
    BenchCase c;
    c.kind = CaseKind::null_coloured;
    c.top = top_of(r, c.top_value);
    c.verdict = r.verdict;
    c.seconds = secs;
    c.findings = static_cast<int>(r.findings.size());
    ++res.coloured_nulls;
    if (c.top >= 0) ++res.coloured_null_findings;
    if (r.verdict == "unexplained") ++res.coloured_null_unexplained;
    if (log) {
      *log += fmt_line("  coloured null (corner %.2f Hz): %s%s\n", s.flicker_corner_hz,
                       r.verdict.c_str(), c.top >= 0 ? "   <-- FINDING" : "");
    }
    c.design = d, c.campaign = base.design, c.pll_reference = base.pll_reference;
    res.cases.push_back(c);
  }
  for (int count : {2, 3}) {
    const std::string save = o.save_multi_dir.empty()
                                 ? std::string()
                                 : o.save_multi_dir + "/design" + std::to_string(d) +
                                       (count == 2 ? "_pair" : "_triple") + ".csv.gz";
    BenchCase c = multi_case(base, null_r, count, g, audit, save);
    if (c.truths.empty()) continue;
    auto& n = count == 2 ? res.pairs : res.triples;
    auto& f = count == 2 ? res.pairs_found : res.triples_found;
    ++n;
    if (c.all_found) ++f;
    if (log) {
      std::string what;
      for (std::size_t k = 0; k < c.truths.size(); ++k)
        what += std::string(k ? " + " : "") + effect_info(static_cast<Effect>(c.truths[k])).id +
                " " + fmt_g(c.true_values[k]) + " (" + fmt_g(c.found_values[k]) + ")";
      *log += fmt_line("  %s -> %s, %d findings%s\n", what.c_str(), c.verdict.c_str(), c.findings,
                       c.all_found ? "" : "   <-- MISS");
    }
    c.design = d, c.campaign = base.design, c.pll_reference = base.pll_reference;
    res.cases.push_back(c);
  }
  BenchCase c = outside_case(base, null_r, g, audit);
  ++res.outside;
  if (c.described) ++res.outside_described;
  if (c.description_matches) ++res.outside_matched;
  if (c.findings > 0) ++res.outside_catalogue;
  if (log) {
    *log += fmt_line("  outside %s %.3g -> %s, %d findings, held-out %.2f x noise%s\n",
                     c.outside.c_str(), c.true_value, c.verdict.c_str(), c.findings,
                     c.heldout_over_noise, c.described ? "" : "   <-- MISS");
  }
  c.design = d, c.campaign = base.design, c.pll_reference = base.pll_reference;
  res.cases.push_back(c);
}

}  // namespace hrg::audit::bench
