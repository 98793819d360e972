// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "audit/audit.hpp"

// The proof of `hrg audit`: recordings from sim_target with one catalogue
// effect concealed at a random sign and a strength of 0.3x-3x its detection
// threshold, and null recordings, in ring-down and telemetry campaigns; per
// design also a null with 1/f noise, two and three effects at once and one
// effect outside the catalogue.
namespace hrg::audit {

namespace bench {
// Campaign designs: ring-down and envelope-controller telemetry from the
// averaged model, and the firmware's own telemetry (see campaign.hpp).
enum class Design { ringdown, telemetry, firmware };
const char* design_name(Design d);
}  // namespace bench

struct BenchOptions {
  int designs = 10;  // random resonators/campaigns; each gives 1 null + 1 per effect
  // Run only this design of the seed's sequence (0 <= only_design < designs;
  // -1: all): the same recordings, verbose lines and counts as in the full run.
  int only_design = -1;
  uint64_t seed = 1;
  double ringdown_s = 480.0;
  double telemetry_s = 360.0;
  bool firmware = true;  // every third design is the firmware's telemetry
  bool verbose = false;
  unsigned jobs = 1;  // designs simulated and audited in parallel (same result for any count)
  // Per design also a null with 1/f noise, a pair, a triple and one effect
  // outside the catalogue.
  bool extra_cases = true;
  // Each design's null twin (it sets the thresholds) and its cases beyond
  // one effect only: the same recordings as in the full run, the one-effect
  // recordings skipped.
  bool no_singles = false;
  // Where each pair and triple recording is written for auditing by hand
  // (DIR/design<K>_pair.csv.gz, DIR/design<K>_triple.csv.gz; empty: nowhere).
  std::string save_multi_dir;
};

// What a benchmark recording holds: nothing (white or coloured noise), one
// catalogue effect, two or three at once, or one effect outside the catalogue.
enum class CaseKind { null_white, null_coloured, single, pair, triple, outside };

struct BenchCase {
  CaseKind kind = CaseKind::single;
  int design = 0;
  bool pll_reference = false;  // the f_ref_hz column follows the resonance
  bench::Design campaign = bench::Design::ringdown;
  int truth = -1;           // Effect index, -1 = null
  double strength = 0.0;    // multiple of the detection threshold
  double true_value = 0.0;  // catalogue parameter
  int top = -1;             // top finding's Effect index, -1 = none
  double top_value = 0.0;
  std::string verdict;
  double seconds = 0.0;
  // Pairs and triples: every concealed effect and value; hit when each is a
  // finding with its parameter within 20 %.
  std::vector<int> truths;
  std::vector<double> true_values;
  std::vector<double> found_values;  // NaN where the effect is not a finding
  bool all_found = false;
  int findings = 0;  // catalogue findings of the audit
  // Outside the catalogue: the audit describes it (verdict unexplained, a
  // description, no catalogue finding, held-out fit within 1.2x the noise).
  std::string outside;  // generic shape concealed
  bool described = false;
  bool description_matches = false;  // the description's first term is the concealed shape
  double heldout_over_noise = 0.0;   // with the description
};

struct BenchResult {
  std::vector<BenchCase> cases;
  // Rows: true effect (0..8) then null (9); columns: top finding (0..8), none (9).
  std::array<std::array<int, kEffectCount + 1>, kEffectCount + 1> confusion{};
  int above2x = 0, above2x_hits = 0;  // hit = top finding right and parameter within 20 %
  int nulls = 0, null_findings = 0;
  int below1x = 0, below1x_found = 0;
  int unscored = 0;  // cases whose threshold is beyond a physical strength
  int coloured_nulls = 0, coloured_null_findings = 0, coloured_null_unexplained = 0;
  int null_unexplained = 0;
  int pairs = 0, pairs_found = 0, triples = 0, triples_found = 0;
  int outside = 0, outside_described = 0, outside_matched = 0, outside_catalogue = 0;
  double mean_audit_s = 0.0;
};

BenchResult run_benchmark(const BenchOptions& o);
std::string format_benchmark(const BenchResult& r);

}  // namespace hrg::audit
