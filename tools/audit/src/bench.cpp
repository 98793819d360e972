// SPDX-License-Identifier: MIT
#include "audit/bench.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <numbers>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>

#include "batch/batch.hpp"
#include "campaign.hpp"
#include "recording/recording.hpp"

namespace hrg::audit {

namespace {

constexpr double kPi = std::numbers::pi;
using bench::Design;
using bench::kOutsideEffectCount;
using bench::outside_name;
using bench::OutsideEffect;
using bench::Scenario;

// printf into a string (the --verbose lines of one design, printed in order later).
[[gnu::format(printf, 1, 2)]] std::string fmt_line(const char* f, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(buf, sizeof buf, f, ap);
  va_end(ap);
  return buf;
}

// Conceals effect `e` with catalogue value `v` in the scenario.
void conceal(Scenario& s, Effect e, double v, std::mt19937_64& g) {
  auto& fx = s.effects;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  switch (e) {
    case Effect::pickoff_gain_mismatch: fx.pickoff_gain_mismatch = {true, v}; break;
    case Effect::pickoff_phase_mismatch: fx.pickoff_phase_mismatch = {true, v}; break;
    case Effect::pickoff_misalignment: fx.pickoff_misalignment = {true, v}; break;
    case Effect::duffing_stiffness: fx.duffing_stiffness = {true, v}; break;
    case Effect::nonlinear_damping: fx.nonlinear_damping = {true, v}; break;
    case Effect::thermal_frequency: fx.thermal_frequency = {true, v}; break;
    case Effect::thermal_damping: fx.thermal_damping = {true, v}; break;
    case Effect::electrostatic_spring: fx.electrostatic_spring = {true, v}; break;
    case Effect::drive_feedthrough: {
      const double big = std::abs(v), small = big * u(g);
      const bool x_big = u(g) < 0.5;
      fx.drive_feedthrough.enabled = true;
      fx.drive_feedthrough.x_v_per_v = x_big ? big : small;
      fx.drive_feedthrough.y_v_per_v = x_big ? small : big;
      fx.drive_feedthrough.x_phase_deg = 360.0 * u(g);
      fx.drive_feedthrough.y_phase_deg = 360.0 * u(g);
      break;
    }
    case Effect::gap_harmonics: {
      // |eps| = |v| along a drawn direction of the 4 theta circle.
      const double dir = 2.0 * kPi * u(g);
      s.electrodes.eps_p = std::abs(v) * std::cos(dir);
      s.electrodes.eps_q = std::abs(v) * std::sin(dir);
      break;
    }
  }
}

}  // namespace

const char* bench::design_name(Design d) {
  switch (d) {
    case Design::ringdown: return "ring-down";
    case Design::telemetry: return "telemetry";
    case Design::firmware: return "firmware telemetry";
  }
  return "?";
}

bool bench::conceal_by_id(Scenario& s, const std::string& id, double value, uint64_t seed) {
  std::mt19937_64 g(seed);
  for (const auto& info : effect_table()) {
    if (id == info.id) {
      conceal(s, info.effect, value, g);
      return true;
    }
  }
  return false;
}

namespace {

// Designs cycle ring-down, telemetry, firmware (or alternate the first two).
Design design_of(const BenchOptions& o, int d) {
  if (o.firmware) return static_cast<Design>(d % 3);
  return d % 2 == 0 ? Design::ringdown : Design::telemetry;
}

// The top finding is the concealed effect with its parameter within 20 %.
bool is_hit(const BenchCase& c) {
  return c.top == c.truth && std::abs(c.top_value - c.true_value) <= 0.2 * std::abs(c.true_value);
}

int top_of(const AuditResult& r, double& value) {
  if (r.findings.empty()) return -1;
  value = r.findings.front().value;
  return static_cast<int>(r.findings.front().effect);
}

std::string fmt_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

using AuditFn = std::function<std::pair<AuditResult, double>(const recording::Recording&)>;

// The damping may change by at most half over the campaign's amplitude or
// temperature range: beyond that a concealed damping effect is not physical.
bool physical(const Scenario& base, Effect e, double value) {
  const double a_max = 1.3 * base.amplitude_v;
  return !((e == Effect::nonlinear_damping && std::abs(value) * a_max * a_max > 0.5) ||
           (e == Effect::thermal_damping && std::abs(value) * base.temp_swing_c > 0.5));
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

// The cases beyond one catalogue effect of a design: a null with coloured
// noise, a pair, a triple and one effect outside the catalogue.
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

}  // namespace

namespace {

// One design's recordings (its null twin, then one per testable effect) and
// their audits: what run_benchmark adds up. Shares nothing with other designs.
struct DesignPart {
  BenchResult res;
  double audit_s = 0.0;
  int audits = 0;
  std::string log;  // the --verbose lines, printed in design order
};

// The null twin of a design: the same resonator, campaign and noise with
// nothing concealed. Its audit gives the thresholds the effects are set by.
AuditResult run_null(const Scenario& base, int d, const AuditFn& audit, DesignPart& part,
                     bool verbose) {
  auto [null_r, null_s] = audit(bench::simulate(base));
  BenchResult& res = part.res;
  BenchCase nc;
  nc.kind = CaseKind::null_white;
  nc.pll_reference = base.pll_reference;
  nc.design = d;
  nc.campaign = base.design;
  nc.top = top_of(null_r, nc.top_value);
  nc.verdict = null_r.verdict;
  nc.seconds = null_s;
  res.cases.push_back(nc);
  ++res.nulls;
  if (nc.top >= 0) ++res.null_findings;
  if (null_r.verdict == "unexplained") ++res.null_unexplained;
  res.confusion[kEffectCount][nc.top >= 0 ? static_cast<std::size_t>(nc.top) : kEffectCount]++;
  if (verbose) {
    part.log += fmt_line("design %d (%s) null: %s\n", d, bench::design_name(base.design),
                         null_r.verdict.c_str());
  }
  return std::move(null_r);
}

// One catalogue effect concealed at 0.3x-3x its threshold `cand` (read from
// the null twin), audited and counted.
void run_single(const Scenario& base, const CandidateScore& cand, int d, std::mt19937_64& g,
                const AuditFn& audit, DesignPart& part, bool verbose) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  BenchResult& res = part.res;
  BenchCase c;
  c.pll_reference = base.pll_reference;
  c.design = d;
  c.campaign = base.design;
  c.truth = static_cast<int>(cand.effect);
  c.strength = 0.3 + 2.7 * u(g);
  const double sign = u(g) < 0.5 ? -1.0 : 1.0;
  c.true_value = sign * c.strength * cand.threshold;
  if (cand.effect == Effect::drive_feedthrough || cand.effect == Effect::gap_harmonics)
    c.true_value = std::abs(c.true_value);
  // Keep the damping physical: it may change by at most half over the
  // campaign's amplitude or temperature range. A design whose threshold
  // lies beyond that cannot reveal the effect and is not scored.
  if (!physical(base, cand.effect, c.true_value)) {
    ++res.unscored;
    return;
  }
  Scenario s = base;
  conceal(s, cand.effect, c.true_value, g);
  const auto [r, secs] = audit(bench::simulate(s));
  c.top = top_of(r, c.top_value);
  c.verdict = r.verdict;
  c.seconds = secs;
  res.confusion[static_cast<std::size_t>(c.truth)]
               [c.top >= 0 ? static_cast<std::size_t>(c.top) : kEffectCount]++;
  if (c.strength >= 2.0) {
    ++res.above2x;
    if (is_hit(c)) ++res.above2x_hits;
  }
  if (c.strength < 1.0) {
    ++res.below1x;
    if (c.top == c.truth) ++res.below1x_found;
  }
  if (verbose) {
    part.log += fmt_line("  %-24s x%.2f true %.4g -> %s %s %.4g%s\n", effect_info(cand.effect).id,
                         c.strength, c.true_value, r.verdict.c_str(),
                         c.top >= 0 ? effect_info(static_cast<Effect>(c.top)).id : "-", c.top_value,
                         c.strength >= 2.0 && !is_hit(c) ? "   <-- MISS" : "");
  }
  res.cases.push_back(c);
}

DesignPart run_design(const BenchOptions& o, int d) {
  DesignPart part;
  const AuditFn timed_audit = [&part](const recording::Recording& rec) {
    const auto t0 = std::chrono::steady_clock::now();
    AuditResult r = run_audit(rec);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    part.audit_s += s;
    ++part.audits;
    return std::make_pair(std::move(r), s);
  };
  const Design kind = design_of(o, d);
  const uint64_t seed = o.seed * 100003ULL + static_cast<uint64_t>(d);
  Scenario base =
      bench::random_scenario(kind, kind == Design::ringdown ? o.ringdown_s : o.telemetry_s, seed);
  // Every other round of the averaged-model designs is demodulated against
  // a reference that follows the resonance (f_ref_hz per row).
  base.pll_reference = kind != Design::firmware && (d / 3) % 2 == 1;
  // A temperature that does not follow time, so that thermal effects can be
  // told from drifts (the audit's step 8 leaves them ambiguous otherwise).
  base.temp_cycles = true;
  const AuditResult null_r = run_null(base, d, timed_audit, part, o.verbose);
  std::mt19937_64 g(seed ^ 0x9e3779b97f4a7c15ULL);
  for (const auto& cand : null_r.candidates) {
    if (o.no_singles) break;
    if (!cand.testable || !(cand.threshold > 0.0) || !std::isfinite(cand.threshold)) continue;
    run_single(base, cand, d, g, timed_audit, part, o.verbose);
  }
  if (o.extra_cases)
    run_extra_cases(o, base, null_r, d, seed, timed_audit, o.verbose ? &part.log : nullptr,
                    part.res);
  return part;
}

// Adds one design's counts to the total (every counter of BenchResult).
void add_counts(BenchResult& res, const BenchResult& r) {
  res.cases.insert(res.cases.end(), r.cases.begin(), r.cases.end());
  for (std::size_t i = 0; i < res.confusion.size(); ++i)
    for (std::size_t j = 0; j < res.confusion[i].size(); ++j)
      res.confusion[i][j] += r.confusion[i][j];
  res.above2x += r.above2x;
  res.above2x_hits += r.above2x_hits;
  res.nulls += r.nulls;
  res.null_findings += r.null_findings;
  res.null_unexplained += r.null_unexplained;
  res.below1x += r.below1x;
  res.below1x_found += r.below1x_found;
  res.unscored += r.unscored;
  res.coloured_nulls += r.coloured_nulls;
  res.coloured_null_findings += r.coloured_null_findings;
  res.coloured_null_unexplained += r.coloured_null_unexplained;
  res.pairs += r.pairs;
  res.pairs_found += r.pairs_found;
  res.triples += r.triples;
  res.triples_found += r.triples_found;
  res.outside += r.outside;
  res.outside_described += r.outside_described;
  res.outside_matched += r.outside_matched;
  res.outside_catalogue += r.outside_catalogue;
}

}  // namespace

// Designs run in parallel (o.jobs threads) and are added up in design order:
// the same result and output for any thread count.
// With o.only_design set, that design alone (what it gives in the full run).
BenchResult run_benchmark(const BenchOptions& o) {
  if (o.only_design >= o.designs) {
    throw std::invalid_argument("audit-bench: design " + std::to_string(o.only_design) +
                                " is not among the " + std::to_string(o.designs) +
                                " designs (--n must be above --design)");
  }
  const bool one = o.only_design >= 0;
  const auto parts = batch::run_indexed(
      one ? 1 : static_cast<std::size_t>(std::max(o.designs, 0)), o.jobs, [&o, one](std::size_t d) {
        return run_design(o, one ? o.only_design : static_cast<int>(d));
      });
  BenchResult res;
  double audit_s = 0.0;
  int audits = 0;
  for (const DesignPart& p : parts) {
    if (o.verbose) std::fputs(p.log.c_str(), stderr);
    add_counts(res, p.res);
    audit_s += p.audit_s;
    audits += p.audits;
  }
  res.mean_audit_s = audits ? audit_s / audits : 0.0;
  return res;
}

namespace {

double pct(int a, int b) { return b ? 100.0 * a / b : 0.0; }

// Nulls with coloured noise, pairs and triples, effects outside the catalogue
// and the recordings against a reference that follows the resonance.
std::string format_beyond_catalogue(const BenchResult& r) {
  std::string o = "\nBeyond one catalogue effect:\n";
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "  nulls, white noise: no finding %d/%d = %.1f %% (goal >= 98 %%), verdict "
                "unexplained %d\n"
                "  nulls, 1/f noise (corner 0.3-3 Hz): no finding %d/%d = %.1f %% (goal >= 98 %%), "
                "verdict unexplained %d\n",
                r.nulls - r.null_findings, r.nulls, pct(r.nulls - r.null_findings, r.nulls),
                r.null_unexplained, r.coloured_nulls - r.coloured_null_findings, r.coloured_nulls,
                pct(r.coloured_nulls - r.coloured_null_findings, r.coloured_nulls),
                r.coloured_null_unexplained);
  o += buf;
  std::snprintf(buf, sizeof buf,
                "  pairs at 2x-3x threshold, both found within 20 %%: %d/%d = %.1f %% (goal >= 90 "
                "%%)\n  triples at 2x-3x threshold, all found within 20 %%: %d/%d = %.1f %% "
                "(goal >= 90 %%)\n",
                r.pairs_found, r.pairs, pct(r.pairs_found, r.pairs), r.triples_found, r.triples,
                pct(r.triples_found, r.triples));
  o += buf;
  std::snprintf(buf, sizeof buf,
                "  outside the catalogue: unexplained with a description, no catalogue finding, "
                "held-out fit <= 1.2x noise %d/%d = %.1f %% (goal >= 90 %%); the description's "
                "first term the concealed shape %d/%d; a catalogue finding %d/%d (goal 0)\n",
                r.outside_described, r.outside, pct(r.outside_described, r.outside),
                r.outside_matched, r.outside, r.outside_catalogue, r.outside);
  o += buf;
  int pll = 0, pll_hits = 0, pll_above = 0, pll_null_found = 0;
  for (const auto& c : r.cases) {
    if (!c.pll_reference) continue;
    if (c.kind == CaseKind::null_white) ++pll, pll_null_found += c.top >= 0 ? 1 : 0;
    if (c.kind == CaseKind::single && c.strength >= 2.0) {
      ++pll_above;
      if (is_hit(c)) ++pll_hits;
    }
  }
  std::snprintf(buf, sizeof buf,
                "  reference following the resonance (f_ref_hz per row): hits above 2x %d/%d, "
                "nulls with a finding %d/%d\n",
                pll_hits, pll_above, pll_null_found, pll);
  o += buf;
  return o;
}

}  // namespace

namespace {

// The confusion matrix: rows the concealed effect, columns the top finding.
std::string format_confusion(const BenchResult& r) {
  std::string o;
  char buf[128];
  static const char* kShort[kEffectCount + 1] = {"gain",   "phase",  "misal",  "duff",
                                                 "nldamp", "thfreq", "thdamp", "spring",
                                                 "feedth", "gap",    "none"};
  o += "Confusion matrix (rows: concealed effect, columns: top finding)\n";
  o += std::string(26, ' ');
  for (const char* s : kShort) {
    std::snprintf(buf, sizeof buf, "%7s", s);
    o += buf;
  }
  o += "\n";
  for (std::size_t i = 0; i <= kEffectCount; ++i) {
    std::snprintf(
        buf, sizeof buf, "%-26s",
        i < kEffectCount ? effect_info(static_cast<Effect>(i)).id : "(nothing concealed)");
    o += buf;
    for (std::size_t j = 0; j <= kEffectCount; ++j) {
      std::snprintf(buf, sizeof buf, "%7d", r.confusion[i][j]);
      o += buf;
    }
    o += "\n";
  }
  return o;
}

// The headline rates of the one-effect recordings, in total and per design.
std::string format_rates(const BenchResult& r) {
  std::string o;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "\nHit rate above 2x threshold (top finding right, parameter within 20 %%): "
                "%d/%d = %.1f %% (goal >= 95 %%)\n"
                "False-finding rate on null recordings: %d/%d = %.1f %% (goal <= 5 %%)\n"
                "Found below 1x threshold (for reference): %d/%d\n"
                "Not scored (threshold beyond a physical damping change in that design): %d\n",
                r.above2x_hits, r.above2x, pct(r.above2x_hits, r.above2x), r.null_findings, r.nulls,
                pct(r.null_findings, r.nulls), r.below1x_found, r.below1x, r.unscored);
  o += buf;
  o += "By campaign design:\n";
  for (Design kind : {Design::ringdown, Design::telemetry, Design::firmware}) {
    int hits = 0, above = 0, nulls = 0, null_found = 0;
    for (const auto& c : r.cases) {
      if (c.campaign != kind) continue;
      if (c.kind == CaseKind::null_white) {
        ++nulls;
        if (c.top >= 0) ++null_found;
      } else if (c.kind == CaseKind::single && c.strength >= 2.0) {
        ++above;
        if (is_hit(c)) ++hits;
      }
    }
    if (nulls == 0) continue;
    std::snprintf(buf, sizeof buf, "  %-20s hits above 2x %d/%d, nulls with a finding %d/%d\n",
                  bench::design_name(kind), hits, above, null_found, nulls);
    o += buf;
  }
  o += "By effect (one effect above 2x; pairs and triples that hold it, all found):\n";
  for (const auto& info : effect_table()) {
    const int e = static_cast<int>(info.effect);
    int hits = 0, above = 0, multi = 0, multi_found = 0;
    for (const auto& c : r.cases) {
      if (c.kind == CaseKind::single && c.truth == e && c.strength >= 2.0) {
        ++above;
        if (is_hit(c)) ++hits;
      } else if ((c.kind == CaseKind::pair || c.kind == CaseKind::triple) &&
                 std::find(c.truths.begin(), c.truths.end(), e) != c.truths.end()) {
        ++multi;
        if (c.all_found) ++multi_found;
      }
    }
    std::snprintf(buf, sizeof buf, "  %-24s hits above 2x %d/%d, with others %d/%d\n", info.id,
                  hits, above, multi_found, multi);
    o += buf;
  }
  return o;
}

// Confusable pairs of the catalogue, and pickoff effects the baseline's own
// parameters absorbed (a miss above 2x with no finding).
std::string format_confusable(const BenchResult& r) {
  std::string o;
  char buf[256];
  struct Pair {
    Effect a, b;
  };
  const Pair pairs[] = {{Effect::duffing_stiffness, Effect::thermal_frequency},
                        {Effect::duffing_stiffness, Effect::electrostatic_spring},
                        {Effect::thermal_frequency, Effect::electrostatic_spring},
                        {Effect::nonlinear_damping, Effect::thermal_damping},
                        {Effect::pickoff_phase_mismatch, Effect::pickoff_misalignment},
                        {Effect::pickoff_gain_mismatch, Effect::pickoff_misalignment}};
  o += "\nConfusable pairs (cases of one taken for the other, all strengths):\n";
  for (const auto& p : pairs) {
    const auto ia = static_cast<std::size_t>(p.a), ib = static_cast<std::size_t>(p.b);
    int na = 0, nb = 0;
    for (std::size_t j = 0; j <= kEffectCount; ++j)
      na += r.confusion[ia][j], nb += r.confusion[ib][j];
    std::snprintf(buf, sizeof buf, "  %-22s <-> %-22s  %d/%d and %d/%d\n", effect_info(p.a).id,
                  effect_info(p.b).id, r.confusion[ia][ib], na, r.confusion[ib][ia], nb);
    o += buf;
  }
  o += "Against the baseline (effect above 2x threshold absorbed, no finding):\n";
  for (Effect e : {Effect::pickoff_gain_mismatch, Effect::pickoff_phase_mismatch,
                   Effect::pickoff_misalignment}) {
    int n = 0, miss = 0;
    for (const auto& c : r.cases) {
      if (c.kind == CaseKind::single && c.truth == static_cast<int>(e) && c.strength >= 2.0) {
        ++n;
        if (c.top < 0) ++miss;
      }
    }
    std::snprintf(buf, sizeof buf, "  %-22s vs %s: %d/%d\n", effect_info(e).id,
                  e == Effect::pickoff_gain_mismatch ? "damping anisotropy" : "frequency split",
                  miss, n);
    o += buf;
  }
  return o;
}

}  // namespace

std::string format_benchmark(const BenchResult& r) {
  std::string o =
      format_confusion(r) + format_rates(r) + format_confusable(r) + format_beyond_catalogue(r);
  char buf[96];
  std::snprintf(buf, sizeof buf, "\nMean audit time per recording: %.2f s\n", r.mean_audit_s);
  return o + buf;
}

}  // namespace hrg::audit
