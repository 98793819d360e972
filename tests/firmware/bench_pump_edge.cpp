// SPDX-License-Identifier: MIT
// Cost of the do-no-harm steps, for instruction counting under callgrind
// (bench_pump_edge.cmake). The switch-off step check
// (fw::PumpEdgeCheck::add_row) per chain block: `on` rows with the pump on
// only (the per-row part), `cycle` the standard window plan's 1000 rows on
// and 1000 off (the fits of one edge included). The model check
// (fw::Gyro::check_model, every output frame: the estimator's health and the
// compensation's reasons) per call: `check_valid` with the compensation valid,
// `check_reasons` with a check window refused (reasons set). Without valgrind
// it just runs and prints a checksum.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "fakes/fake_board.hpp"
#include "fakes/fake_chain.hpp"
#include "fakes/fake_clock.hpp"
#include "firmware/estimator_port.hpp"
#include "firmware/gyro.hpp"
#include "firmware/pump_edge_check.hpp"
#include "support/short_window_config.hpp"

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

namespace {

// The firmware (real estimator, envelope-level chain turning the pattern, as
// test_no_allocation) run until its model is in force and checked: valid,
// or with every check window refused (reasons set). Returns the frames run.
int run_to_model(hrg::fw::Gyro& g) {
  for (int i = 1; i <= 200000; ++i) {
    g.run_frame();
    const hrg::fw::GyroStatus& s = g.status();
    if (s.compensation_valid || s.model_checks_failed > 0) return i;
  }
  return -1;
}

hrg::fw::GyroConfig model_check_config(bool refuse) {
  hrg::fw::GyroConfig c = hrg::test::short_window_config();
  c.windows.check_period_frames = 2000;
  // Every check window's misfit below this: refused.
  if (refuse) c.min_window_misfit = 1e9;
  return c;
}

}  // namespace

// `calls` output frames' model checks of a firmware in that state (the
// output task, whose first step it is; callgrind counts check_model alone).
extern "C" __attribute__((noinline)) double hrg_bench_model_check(hrg::fw::Gyro& g, int calls) {
  double sum = 0;
  for (int k = 0; k < calls; ++k) {
    hrg::fw::Gyro::task_output(g);
    sum += g.status().compensation_reasons;
  }
  return sum;
}

int model_check(bool refuse, int calls) {
  hrg::fakes::FakeBoard b;
  hrg::fakes::FakeClock timer;
  hrg::fakes::FakeChain chain;
  chain.theta_rate_rad_per_block = 2e-4;  // the pattern turns: windows land in many bins
  chain.decay_per_block = 3e-6;           // nu = 3e-3 1/s at 1 kHz
  hrg::est::Estimator::Config ec;
  hrg::fw::EstimatorPort ident(ec);
  hrg::fw::Gyro g(b.board, chain, ident, timer, hrg::fw::Pacing::lockstep,
                  model_check_config(refuse));
  const int frames = run_to_model(g);
  const hrg::fw::GyroStatus& s = g.status();
  if (frames < 0 || s.compensation_valid == refuse) {
    std::fprintf(stderr, "the firmware did not reach the %s model check\n",
                 refuse ? "refused" : "valid");
    return 1;
  }
  const double sum = hrg_bench_model_check(g, calls);
  std::printf("%s: after %d frames, reasons 0x%02x, %d calls, checksum %.9g\n",
              refuse ? "check_reasons" : "check_valid", frames, s.compensation_reasons, calls, sum);
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s on|cycle|check_valid|check_reasons N\n", argv[0]);
    return 2;
  }
  const int n = std::atoi(argv[2]);
  if (std::strcmp(argv[1], "check_valid") == 0) return model_check(false, n);
  if (std::strcmp(argv[1], "check_reasons") == 0) return model_check(true, n);
  int period = 0;
  if (std::strcmp(argv[1], "cycle") == 0) {
    period = 2000;
  } else if (std::strcmp(argv[1], "on") != 0) {
    std::fprintf(stderr, "unknown mode '%s'\n", argv[1]);
    return 2;
  }
  std::printf("%s: %d rows, checksum %.9g\n", argv[1], n, hrg_bench_pump_edge(n, period));
  return 0;
}
