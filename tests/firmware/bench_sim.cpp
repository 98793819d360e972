// SPDX-License-Identifier: MIT
// Benchmark (prints figures): firmware + sim_target in lockstep, simulated
// seconds per wall and per CPU second at fs = 100 kHz on one core; then the
// same executive paced in real time, per-task worst-case time. Speed is only
// printed; what the run must do is asserted: in lockstep every frame and every
// task run happens (the executive never skips one), the gyro reaches operate.
#include <cstdio>

#include "sim_run/report.hpp"
#include "sim_run/run.hpp"

#include "support/cpputest.hpp"

namespace {
void print_tasks(const hrg::sim_run::RunResult& r) {
  for (const auto& t : r.tasks) {
    std::printf("  %-10s %5u Hz budget %6.1f us  max %8.1f us  mean %7.2f us  overruns %u\n",
                t.name.c_str(), t.rate_hz, t.budget_ns / 1e3, t.max_ns / 1e3, t.mean_ns / 1e3,
                t.overruns);
  }
  for (const auto& t : r.tasks) {
    if (t.name == "chain") {
      std::printf("  chain without the simulated ADC (resonator physics): mean %.2f us\n",
                  t.mean_ns / 1e3 - r.adc_wait_mean_us);
    }
  }
  std::printf("  frames %llu, missed %u, deadline misses %u, max frame %.1f us\n",
              static_cast<unsigned long long>(r.frames.frames), r.frames.missed_frames,
              r.frames.deadline_misses, r.frames.max_frame_ns / 1e3);
}

void run_benchmark() {
  auto job = hrg::sim_run::default_run(60.0, 16);
  hrg::sim_run::RunOptions opt;
  const auto r = hrg::sim_run::run_simulation(job, opt);
  std::printf("\nlockstep, fs %u Hz, %.0f simulated s:\n", job.sim.adc.sample_rate_hz, r.sim_s);
  std::printf("  realtime factor %.1f x wall (%.2f s), %.1f x CPU (%.2f s); goal >= 200\n",
              r.realtime_factor, r.wall_s, r.realtime_factor_cpu, r.cpu_s);
  // The goal is held by CPU time: the wall-clock share moves with where the
  // loaded machine's preemptions land.
  std::printf(
      "  share in the simulated target (resonator + converters): %s; goal <= 40 %% by CPU "
      "time\n",
      hrg::sim_run::describe_share(r).c_str());
  print_tasks(r);
  CHECK_TRUE(r.reached_operate);
  const auto frames = static_cast<uint64_t>(r.sim_s * hrg::fw::kBaseRateHz);
  CHECK_EQUAL(frames, r.frames.frames);
  LONGS_EQUAL(0, r.frames.missed_frames);
  for (const auto& t : r.tasks)
    CHECK_EQUAL(frames / (hrg::fw::kBaseRateHz / t.rate_hz), t.runs);

  auto rt_job = hrg::sim_run::default_run(5.0, 16);
  opt.real_time = true;
  const auto rt = hrg::sim_run::run_simulation(rt_job, opt);
  std::printf("real time (CLOCK_MONOTONIC, 1 ms frames, %s), %.0f s:\n", rt.realtime_setup.c_str(),
              rt.sim_s);
  print_tasks(rt);
  // Paced by the wall clock: frames run or are counted as missed, never lost.
  CHECK_TRUE(rt.frames.frames + rt.frames.missed_frames >=
             static_cast<uint64_t>(rt.sim_s * hrg::fw::kBaseRateHz) - 1);
}
}  // namespace

TEST_GROUP(BenchSim){};

TEST(BenchSim, LockstepSpeedAndRealTimeTaskTimes) {
  // The simulated target is a process-wide instance that keeps its buffers:
  // the leak checker is off while it runs.
  MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads();
  run_benchmark();
  MemoryLeakWarningPlugin::restoreNewDeleteOverloads();
}
