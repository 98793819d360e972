// SPDX-License-Identifier: MIT
// The benchmark's printed result (format_benchmark): the confusion matrix,
// the rates against their goals, the confusable pairs and the cases beyond
// one catalogue effect.
#include "audit/bench.hpp"

#include <cstdio>
#include <string>

#include "bench_cases.hpp"

namespace hrg::audit {

namespace {

using bench::Design;
using bench::is_hit;

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
