// SPDX-License-Identifier: MIT
// Cost of the switch-off step check (fw::PumpEdgeCheck::add_row) per chain
// block, for instruction counting under callgrind (bench_pump_edge.cmake):
// `on` rows with the pump on only (the per-row part), `cycle` the standard
// window plan's 1000 rows on and 1000 off (the fits of one edge included).
// Without valgrind it just runs and prints a checksum.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/pump_edge_check.hpp"

using hrg::fw::ChainRecord;
using hrg::fw::PumpEdgeCheck;

namespace {

ChainRecord row(int i) {
  ChainRecord r{};
  r.quad_v = {0.8 + i * 1e-9, -0.05, 0.6, 0.02 + i * 1e-9};
  r.pump_v = 3.0;
  r.pump_seen_v = 3.0;
  r.pump_phase_rad = 0.7;
  r.wave.a_A_v = 1.0;
  r.nco_phase = static_cast<uint32_t>(i) * 0x9e3779b9u;
  return r;
}

}  // namespace

extern "C" __attribute__((noinline)) double hrg_bench_pump_edge(int rows, int period) {
  PumpEdgeCheck c{hrg::fw::PumpEdgeCheckConfig{}};
  for (int i = 0; i < rows; ++i) {
    const bool on = period == 0 || (i % period) < period / 2;
    c.add_row(row(i), on, true);
  }
  return c.status().step_v + c.status().edges;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s on|cycle ROWS\n", argv[0]);
    return 2;
  }
  const int rows = std::atoi(argv[2]);
  int period = 0;
  if (std::strcmp(argv[1], "cycle") == 0) {
    period = 2000;
  } else if (std::strcmp(argv[1], "on") != 0) {
    std::fprintf(stderr, "unknown mode '%s'\n", argv[1]);
    return 2;
  }
  std::printf("%s: %d rows, checksum %.9g\n", argv[1], rows, hrg_bench_pump_edge(rows, period));
  return 0;
}
