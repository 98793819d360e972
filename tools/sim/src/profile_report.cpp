// SPDX-License-Identifier: MIT
#include "sim_run/profile_report.hpp"

#include <algorithm>
#include <cstdio>

namespace hrg::sim_run {

namespace {

// One line: seconds in total, microseconds per base frame, share of the loop.
void line(std::string& out, const char* what, double total_s, double frames, double loop_s) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "  %-36s %9.3f s %9.2f us %6.1f %%\n", what, total_s,
                frames > 0 ? 1e6 * total_s / frames : 0.0,
                loop_s > 0 ? 100.0 * total_s / loop_s : 0.0);
  out += buf;
}

}  // namespace

std::string format_profile(const RunResult& r) {
  std::string out;
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "profile (lockstep, host time): %.1f simulated s in %.2f s wall (%.1fx) and "
                "%.2f s CPU, user+sys (%.1fx per CPU second)\n",
                r.sim_s, r.wall_s, r.realtime_factor, r.cpu_s, r.realtime_factor_cpu);
  out += buf;
  std::snprintf(buf, sizeof buf, "  %-36s %11s %12s %8s\n", "where", "total", "per frame",
                "of loop");
  out += buf;
  const double loop_s = r.wall_s;
  double frames = 0.0;
  double tasks_s = 0.0;
  for (const auto& t : r.tasks) {
    frames = std::max(frames, static_cast<double>(t.runs));
    tasks_s += t.mean_ns * 1e-9 * static_cast<double>(t.runs);
  }
  const auto& st = r.sim_stages;
  const double adc_s = r.adc_wait_mean_us * 1e-6 * frames;
  for (const auto& t : r.tasks) {
    const double task_s = t.mean_ns * 1e-9 * static_cast<double>(t.runs);
    if (t.name != "chain") {
      line(out, ("task " + t.name).c_str(), task_s, frames, loop_s);
      continue;
    }
    line(out, "task chain, its own DSP", task_s - adc_s, frames, loop_s);
    line(out, "task chain, ADC read: simulated target", adc_s, frames, loop_s);
    const double staged_s = 1e-9 * static_cast<double>(st.dac_ns + st.resonator_ns + st.noise_ns +
                                                       st.adc_ns + st.block_ns);
    line(out, "  DAC queue and drive quantisers", 1e-9 * static_cast<double>(st.dac_ns), frames,
         loop_s);
    line(out, "  resonator (pickoffs, full-rate step)", 1e-9 * static_cast<double>(st.resonator_ns),
         frames, loop_s);
    line(out, "  pickoff noise", 1e-9 * static_cast<double>(st.noise_ns), frames, loop_s);
    line(out, "  ADC quantiser and faults", 1e-9 * static_cast<double>(st.adc_ns), frames, loop_s);
    line(out, "  per block (angles, CAN bus time)", 1e-9 * static_cast<double>(st.block_ns), frames,
         loop_s);
    line(out, "  call and timing overhead", adc_s - staged_s, frames, loop_s);
  }
  line(out, "job loop outside the tasks (truth, rows)", loop_s - tasks_s, frames, loop_s);
  if (st.samples == 0) {
    out += "  (stage times need the profile option)\n";
  } else {
    out +=
        "  (the stages timed one by one; without --profile the resonator step and the pickoff\n"
        "   noise share one loop, with the same bits, and the run is faster than shown here)\n";
  }
  return out;
}

}  // namespace hrg::sim_run
