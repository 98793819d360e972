// SPDX-License-Identifier: MIT
// The benchmark's designs: each a random resonator and campaign, its null
// twin and one recording per catalogue effect, run in parallel and added up
// in design order (run_benchmark).
#include "audit/bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "batch/batch.hpp"
#include "bench_cases.hpp"
#include "campaign.hpp"
#include "recording/recording.hpp"

namespace hrg::audit {

namespace bench {

namespace {

constexpr double kPi = std::numbers::pi;

}  // namespace

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

}  // namespace bench

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

using bench::AuditFn;
using bench::Design;
using bench::fmt_line;
using bench::is_hit;
using bench::Scenario;
using bench::top_of;

// Designs cycle ring-down, telemetry, firmware (or alternate the first two).
Design design_of(const BenchOptions& o, int d) {
  if (o.firmware) return static_cast<Design>(d % 3);
  return d % 2 == 0 ? Design::ringdown : Design::telemetry;
}

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

}  // namespace hrg::audit
