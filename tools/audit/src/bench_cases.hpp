// SPDX-License-Identifier: MIT
#pragma once

// What the benchmark's designs (bench.cpp) and their cases beyond one
// effect (bench_cases.cpp) share: concealing an effect, scoring a case
// against the audit's top finding, and the --verbose lines. Private to
// tools/audit/src.

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <utility>

#include "audit/audit.hpp"
#include "audit/bench.hpp"
#include "campaign.hpp"
#include "recording/recording.hpp"

namespace hrg::audit::bench {

using AuditFn = std::function<std::pair<AuditResult, double>(const recording::Recording&)>;

// printf into a string (the --verbose lines of one design, printed in order later).
[[gnu::format(printf, 1, 2)]] std::string fmt_line(const char* f, ...);

// Conceals effect `e` with catalogue value `v` in the scenario.
void conceal(Scenario& s, Effect e, double v, std::mt19937_64& g);

// The top finding is the concealed effect with its parameter within 20 %.
bool is_hit(const BenchCase& c);

// The top finding's effect index (-1: none) and, in `value`, its value.
int top_of(const AuditResult& r, double& value);

// Whether effect `e` concealed at `value` keeps the damping physical in the
// campaign (bench_cases.cpp says how).
bool physical(const Scenario& base, Effect e, double value);

// The cases beyond one catalogue effect of a design: a null with coloured
// noise, a pair, a triple and one effect outside the catalogue.
void run_extra_cases(const BenchOptions& o, const Scenario& base, const AuditResult& null_r, int d,
                     uint64_t seed, const AuditFn& audit, std::string* log, BenchResult& res);

}  // namespace hrg::audit::bench
