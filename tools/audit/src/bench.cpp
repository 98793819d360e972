// SPDX-License-Identifier: MIT
#include "audit/bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <random>
#include <string>

#include "batch/batch.hpp"
#include "campaign.hpp"

namespace hrg::audit {

namespace {

using bench::Design;
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

DesignPart run_design(const BenchOptions& o, int d) {
  DesignPart part;
  BenchResult& res = part.res;
  double& audit_s = part.audit_s;
  int& audits = part.audits;
  auto timed_audit = [&](const recording::Recording& rec) {
    const auto t0 = std::chrono::steady_clock::now();
    AuditResult r = run_audit(rec);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    audit_s += s;
    ++audits;
    return std::make_pair(r, s);
  };
  {
    const Design kind = design_of(o, d);
    const uint64_t seed = o.seed * 100003ULL + static_cast<uint64_t>(d);
    const Scenario base =
        bench::random_scenario(kind, kind == Design::ringdown ? o.ringdown_s : o.telemetry_s, seed);
    // Null twin: the same resonator, campaign and noise with nothing concealed.
    const auto [null_r, null_s] = timed_audit(bench::simulate(base));
    BenchCase nc;
    nc.design = d;
    nc.campaign = kind;
    nc.top = top_of(null_r, nc.top_value);
    nc.verdict = null_r.verdict;
    nc.seconds = null_s;
    res.cases.push_back(nc);
    ++res.nulls;
    if (nc.top >= 0) ++res.null_findings;
    res.confusion[kEffectCount][nc.top >= 0 ? static_cast<std::size_t>(nc.top) : kEffectCount]++;
    if (o.verbose) {
      part.log += fmt_line("design %d (%s) null: %s\n", d, bench::design_name(kind),
                           null_r.verdict.c_str());
    }
    std::mt19937_64 g(seed ^ 0x9e3779b97f4a7c15ULL);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const auto& cand : null_r.candidates) {
      if (!cand.testable || !(cand.threshold > 0.0) || !std::isfinite(cand.threshold)) continue;
      BenchCase c;
      c.design = d;
      c.campaign = kind;
      c.truth = static_cast<int>(cand.effect);
      c.strength = 0.3 + 2.7 * u(g);
      const double sign = u(g) < 0.5 ? -1.0 : 1.0;
      c.true_value = sign * c.strength * cand.threshold;
      if (cand.effect == Effect::drive_feedthrough) c.true_value = std::abs(c.true_value);
      // Keep the damping physical: it may change by at most half over the
      // campaign's amplitude or temperature range. A design whose threshold
      // lies beyond that cannot reveal the effect and is not scored.
      const double a_max = 1.3 * base.amplitude_v;
      if ((cand.effect == Effect::nonlinear_damping &&
           std::abs(c.true_value) * a_max * a_max > 0.5) ||
          (cand.effect == Effect::thermal_damping &&
           std::abs(c.true_value) * base.temp_swing_c > 0.5)) {
        ++res.unscored;
        continue;
      }
      Scenario s = base;
      conceal(s, cand.effect, c.true_value, g);
      const auto [r, secs] = timed_audit(bench::simulate(s));
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
      if (o.verbose) {
        part.log +=
            fmt_line("  %-24s x%.2f true %.4g -> %s %s %.4g%s\n", effect_info(cand.effect).id,
                     c.strength, c.true_value, r.verdict.c_str(),
                     c.top >= 0 ? effect_info(static_cast<Effect>(c.top)).id : "-", c.top_value,
                     c.strength >= 2.0 && !is_hit(c) ? "   <-- MISS" : "");
      }
      res.cases.push_back(c);
    }
  }
  return part;
}

}  // namespace

// Designs run in parallel (o.jobs threads) and are added up in design order:
// the same result and output for any thread count.
BenchResult run_benchmark(const BenchOptions& o) {
  const auto parts =
      batch::run_indexed(static_cast<std::size_t>(std::max(o.designs, 0)), o.jobs,
                         [&o](std::size_t d) { return run_design(o, static_cast<int>(d)); });
  BenchResult res;
  double audit_s = 0.0;
  int audits = 0;
  for (const DesignPart& p : parts) {
    if (o.verbose) std::fputs(p.log.c_str(), stderr);
    const BenchResult& r = p.res;
    res.cases.insert(res.cases.end(), r.cases.begin(), r.cases.end());
    for (std::size_t i = 0; i < res.confusion.size(); ++i)
      for (std::size_t j = 0; j < res.confusion[i].size(); ++j)
        res.confusion[i][j] += r.confusion[i][j];
    res.above2x += r.above2x;
    res.above2x_hits += r.above2x_hits;
    res.nulls += r.nulls;
    res.null_findings += r.null_findings;
    res.below1x += r.below1x;
    res.below1x_found += r.below1x_found;
    res.unscored += r.unscored;
    audit_s += p.audit_s;
    audits += p.audits;
  }
  res.mean_audit_s = audits ? audit_s / audits : 0.0;
  return res;
}

std::string format_benchmark(const BenchResult& r) {
  std::string o;
  char buf[512];
  static const char* kShort[kEffectCount + 1] = {"gain",   "phase",  "misal",  "duff",   "nldamp",
                                                 "thfreq", "thdamp", "spring", "feedth", "none"};
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
  std::snprintf(buf, sizeof buf,
                "\nHit rate above 2x threshold (top finding right, parameter within 20 %%): "
                "%d/%d = %.1f %% (goal >= 95 %%)\n",
                r.above2x_hits, r.above2x, r.above2x ? 100.0 * r.above2x_hits / r.above2x : 0.0);
  o += buf;
  std::snprintf(buf, sizeof buf,
                "False-finding rate on null recordings: %d/%d = %.1f %% (goal <= 5 %%)\n",
                r.null_findings, r.nulls, r.nulls ? 100.0 * r.null_findings / r.nulls : 0.0);
  o += buf;
  std::snprintf(buf, sizeof buf, "Found below 1x threshold (for reference): %d/%d\n",
                r.below1x_found, r.below1x);
  o += buf;
  std::snprintf(buf, sizeof buf,
                "Not scored (threshold beyond a physical damping change in that design): %d\n",
                r.unscored);
  o += buf;
  o += "By campaign design:\n";
  for (Design kind : {Design::ringdown, Design::telemetry, Design::firmware}) {
    int hits = 0, above = 0, nulls = 0, null_found = 0;
    for (const auto& c : r.cases) {
      if (c.campaign != kind) continue;
      if (c.truth < 0) {
        ++nulls;
        if (c.top >= 0) ++null_found;
      } else if (c.strength >= 2.0) {
        ++above;
        if (is_hit(c)) ++hits;
      }
    }
    if (nulls == 0) continue;
    std::snprintf(buf, sizeof buf, "  %-20s hits above 2x %d/%d, nulls with a finding %d/%d\n",
                  bench::design_name(kind), hits, above, null_found, nulls);
    o += buf;
  }
  // Confusable pairs of the catalogue.
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
  // Against the baseline's own parameters: a miss above 2x means the
  // baseline (damping anisotropy, split) absorbed the effect.
  o += "Against the baseline (effect above 2x threshold absorbed, no finding):\n";
  for (Effect e : {Effect::pickoff_gain_mismatch, Effect::pickoff_phase_mismatch,
                   Effect::pickoff_misalignment}) {
    int n = 0, miss = 0;
    for (const auto& c : r.cases) {
      if (c.truth == static_cast<int>(e) && c.strength >= 2.0) {
        ++n;
        if (c.top < 0) ++miss;
      }
    }
    std::snprintf(buf, sizeof buf, "  %-22s vs %s: %d/%d\n", effect_info(e).id,
                  e == Effect::pickoff_gain_mismatch ? "damping anisotropy" : "frequency split",
                  miss, n);
    o += buf;
  }
  std::snprintf(buf, sizeof buf, "\nMean audit time per recording: %.2f s\n", r.mean_audit_s);
  o += buf;
  return o;
}

}  // namespace hrg::audit
