// SPDX-License-Identifier: MIT
// Benchmark (label bench): prints the full-rate resonator's samples per second,
// the averaged model's simulated seconds per wall second, and the comparison
// with SciPy's DOP853 on the same free-decay ODE (tests/sim_target/scipy_compare.py).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "hal/board.hpp"
#include "sim_target/averaged_model.hpp"
#include "sim_target/control.hpp"
#include "sim_target/resonator.hpp"

using namespace hrg::sim;

namespace {

// Process CPU time: the CI machine is shared, so rates are per CPU second of this
// process (wall time would count the other jobs too).
struct Clock {
  std::clock_t cpu = std::clock();
  std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
};
double cpu_since(const Clock& c) {
  return static_cast<double>(std::clock() - c.cpu) / CLOCKS_PER_SEC;
}
double wall_since(const Clock& c) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - c.wall).count();
}

ResonatorParams bench_params() {
  ResonatorParams p;
  p.th_mu_rad = 0.2;
  p.th_w_rad = 0.5;
  return p;
}

void full_rate(const char* what, Resonator r, const Drive& d, long samples) {
  const Clock t0;
  for (long i = 0; i < samples; ++i)
    r.step(d, 1e-5);
  const double per_s = static_cast<double>(samples) / cpu_since(t0);
  std::printf("full rate, %-48s %6.1f M samples/CPU-s (%5.0fx real time at 100 kHz), x = %+.6f\n",
              what, per_s / 1e6, per_s / 1e5, r.x_v());
}

void averaged(const char* what, AveragedModel m, double step_s, double total_s) {
  const Clock t0;
  const long n = std::lround(total_s / step_s);
  double sink = 0.0;
  for (long i = 0; i < n; ++i) {
    m.advance(step_s);
    sink += m.demodulated().cx_v;
  }
  const double wall = cpu_since(t0);
  std::printf("averaged,  %-48s %9.3g simulated s per CPU-s (%ld outputs, sum %.3g)\n", what,
              total_s / wall, n, sink);
}

// The simulated board in lockstep blocks of 100 frames under a held 1.25 V
// DAC word on every channel: frames per CPU second, best of three passes.
double board_frames_per_s(const SimConfig& cfg, int blocks) {
  double best = 0.0;
  for (int pass = 0; pass < 3; ++pass) {
    target().configure(cfg);
    hrg::hal::Board& b = hrg::hal::board();
    b.excitation_enable.write(true);
    std::vector<hrg::hal::q31_t> adc(200);
    std::vector<hrg::hal::q31_t> dac(300, 1 << 28);
    uint64_t t_ns = 0;
    uint32_t clipped = 0;
    const Clock t0;
    for (int k = 0; k < blocks; ++k) {
      b.dac.write_block(dac);
      b.adc.read_block(adc, t_ns, clipped);
    }
    best = std::max(best, blocks * 100.0 / cpu_since(t0));
  }
  return best;
}

}  // namespace

int main() {
  const ResonatorParams p = bench_params();
  Resonator r(p);
  r.set_rate_profile(Profile::constant(100 * kDegToRad));
  r.set_standing_wave(1.0, 0.3);
  full_rate("free decay, Omega = 100 deg/s:", r, {}, 20'000'000);
  Resonator rs(p);
  rs.set_rate_profile(Profile::sine(100 * kDegToRad, 1.0, 0.0));
  rs.set_standing_wave(1.0, 0.3);
  full_rate("free decay, Omega = 100 deg/s sin(2 pi 1 Hz t):", rs, {}, 10'000'000);
  Resonator rp(p);
  rp.set_standing_wave(1.0, 0.3);
  full_rate("pump 3 V held (pump term active):", rp, Drive{3.0, 0.5, 0.0}, 10'000'000);

  {
    // The whole simulated board: ADC (noise, quantisation) + DAC + resonator, lockstep blocks.
    SimConfig cfg;
    cfg.resonator = p;
    cfg.adc.noise_v_rms = {2.2e-4, 2.2e-4};
    cfg.initial.amplitude_v = 1.0;
    const double per_s = board_frames_per_s(cfg, 20'000);
    std::printf(
        "simulated board (ADC noise + DAC + resonator):       %6.1f M frames/CPU-s (%5.0fx real "
        "time)\n",
        per_s / 1e6, per_s / 1e5);
    // The same board while the rate table ramps (the default run's 10 deg/s^2
    // ramps, back and forth) and held at the ramps' top rate: ns per frame.
    cfg.dac.latency_samples = 2;
    cfg.rate_rad_s = Profile::constant(10.0 * kDegToRad);
    const double held_ns = 1e9 / board_frames_per_s(cfg, 20'000);
    std::vector<ProfilePoint> triangle;
    for (int i = 0; i <= 20; ++i)
      triangle.push_back({static_cast<double>(i), (i % 2) * 10.0 * kDegToRad});
    cfg.rate_rad_s = Profile::ramps(triangle);
    const double ramp_ns = 1e9 / board_frames_per_s(cfg, 20'000);
    std::printf("simulated board, rate held / ramping at 10 deg/s^2:  %5.2f / %5.2f ns per frame\n",
                held_ns, ramp_ns);
  }

  AveragedModel m(p);
  m.set_rate_profile(Profile::constant(100 * kDegToRad));
  m.set_standing_wave(1.0, 0.3);
  averaged("free decay, output every 1 s:", m, 1.0, 1e7);
  averaged("free decay, output every 0.1 s:", m, 0.1, 1e6);
  averaged("free decay, output every 1 ms:", m, 1e-3, 1e4);
  AveragedModel ms = m;
  ms.set_rate_profile(Profile::sine(100 * kDegToRad, 0.01, 0.0));
  averaged("sine rate (10 ms midpoint steps), output 1 s:", ms, 1.0, 2e4);
  AveragedModel mp(p);
  mp.set_standing_wave(1.0, 0.3);
  EnvelopeDrive d;
  d.excitation = true;
  d.pump_v = 3.0;
  d.pump_phase_rad = kPi / 4;
  mp.set_drive(d);
  averaged("pump following the wave, output every 1 s:", mp, 1.0, 2e3);

  // Side by side with SciPy: the same free-decay ODE over 0.2 s.
  const double rate = 100 * kDegToRad;
  Resonator c(p);
  c.set_rate_profile(Profile::constant(rate));
  c.set_standing_wave(1.0, 0.3);
  const std::string traj = "bench_sim_target_traj.csv";
  std::FILE* f = std::fopen(traj.c_str(), "w");
  if (!f) return 1;
  const long samples = 20'000;
  std::string rows = "t_s,x_v,y_v,vx,vy\n";
  char line[160];
  for (long i = 0; i <= samples; ++i) {
    if (i % 100 == 0) {
      std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g\n", c.time_s(), c.x_v(),
                    c.y_v(), c.vx_v_per_s(), c.vy_v_per_s());
      rows += line;
    }
    if (i < samples) c.step({}, 1e-5);
  }
  // Time the integration alone (the loop above also formats the rows), 50 times over.
  const int repeats = 50;
  double x_end = 0.0;
  const Clock t1;
  for (int k = 0; k < repeats; ++k) {
    Resonator c2(p);
    c2.set_rate_profile(Profile::constant(rate));
    c2.set_standing_wave(1.0, 0.3);
    for (long i = 0; i < samples; ++i)
      c2.step({}, 1e-5);
    x_end += c2.x_v();
  }
  const double wall = wall_since(t1) / repeats;
  const double cpu = cpu_since(t1) / repeats;
  std::fprintf(f, "# f_hz=%.17g\n# q=%.17g\n# dmu=%.17g\n# th_mu_rad=%.17g\n# split_hz=%.17g\n",
               p.f_hz, p.q, p.dmu, p.th_mu_rad, p.split_hz);
  std::fprintf(
      f,
      "# th_w_rad=%.17g\n# angular_gain=%.17g\n# rate_rad_s=%.17g\n# wall_s=%.9g\n# cpu_s=%.9g\n%s",
      p.th_w_rad, p.angular_gain, rate, wall, cpu, rows.c_str());
  std::fclose(f);
  std::printf(
      "sim_target full rate: 0.2 s (20000 samples) in %.6f s wall, %.6f s CPU, final x %+.9f\n",
      wall, cpu, x_end / repeats);
  const std::string cmd = std::string("/usr/bin/python3 ") + HRG_SCIPY_COMPARE + " " + traj;
  std::fflush(stdout);
  const int rc = std::system(cmd.c_str());
  return rc == 0 ? 0 : 1;
}
