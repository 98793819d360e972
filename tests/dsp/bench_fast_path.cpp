// SPDX-License-Identifier: MIT
// Fast path of the chain (NCO, mixing, sinc^5 decimation, both channels) for
// instruction counting under callgrind: bench_fast_path.cmake runs
//   valgrind --tool=callgrind --toggle-collect=hrg_bench_fast_path_<type>
// and divides the instructions by the frames processed. Without valgrind the
// program just runs (and prints the outputs so nothing is optimised away).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <vector>

#include "dsp/chain.hpp"
#include "dsp/demodulator.hpp"
#include "dsp/fixed.hpp"
#include "dsp/nco.hpp"
#include "dsp/pickoff_correction.hpp"

using namespace hrg::dsp;

namespace {
constexpr uint32_t kL = 100;

template <typename T>
double run(const std::vector<q31_t>& frames, int blocks) {
  Demodulator<T> d(kL);
  uint32_t phase = 0;
  const uint32_t step = phase_step_of_hz(5000.0, 100000.0);
  QuadSample<T> q;
  double sum = 0.0;
  for (int b = 0; b < blocks; ++b) {
    d.process_block(frames, phase, step, q);
    sum += SampleOps<T>::to_f64(q.cx) + SampleOps<T>::to_f64(q.sy);
  }
  return sum;
}
// Whole chain per block (fast path, wave variables, loops, synthesis), with
// excitation on so every part runs; `corrected`: with a pickoff map's
// inverse (gain 1 %, phase 1 deg, misalignment 0.5 deg) and a drive
// feedthrough on both channels in force.
template <typename T>
double run_chain(const std::vector<q31_t>& frames, int blocks, bool corrected) {
  ChainConfig cfg;
  cfg.f_center_hz = 5000.2;
  static Chain<T> chain(cfg);
  chain.reset();
  chain.set_excitation(true);
  if (corrected) {
    const double deg = std::numbers::pi / 180.0;
    PickoffMap map;
    map.y_gain = 0.01;
    map.y_phase_rad = 1.0 * deg;
    map.y_misalignment_rad = 0.5 * deg;
    PickoffCorrection<double> k;
    const FeedthroughCoefficients<double> ft{8.7e-4, 5e-4, 4.3e-4, 2.5e-4};
    if (!pickoff_correction_of(map, k) || !chain.set_electronics_correction(k, ft)) return 0.0;
  } else {
    chain.clear_electronics_correction();
  }
  std::vector<q31_t> dac(3 * kL);
  double sum = 0.0;
  for (int b = 0; b < blocks; ++b) {
    chain.process(frames, dac);
    sum += chain.outputs().theta_A_rad + static_cast<double>(dac[7]);
  }
  return sum;
}
}  // namespace

extern "C" __attribute__((noinline)) double hrg_bench_chain_q31(const std::vector<q31_t>& f,
                                                                int blocks) {
  return run_chain<q31_t>(f, blocks, false);
}
extern "C" __attribute__((noinline)) double hrg_bench_chain_f32(const std::vector<q31_t>& f,
                                                                int blocks) {
  return run_chain<float>(f, blocks, false);
}
extern "C" __attribute__((noinline)) double hrg_bench_chain_q31_cal(const std::vector<q31_t>& f,
                                                                    int blocks) {
  return run_chain<q31_t>(f, blocks, true);
}
extern "C" __attribute__((noinline)) double hrg_bench_chain_f32_cal(const std::vector<q31_t>& f,
                                                                    int blocks) {
  return run_chain<float>(f, blocks, true);
}

extern "C" __attribute__((noinline)) double hrg_bench_fast_path_q31(const std::vector<q31_t>& f,
                                                                    int blocks) {
  return run<q31_t>(f, blocks);
}
extern "C" __attribute__((noinline)) double hrg_bench_fast_path_f32(const std::vector<q31_t>& f,
                                                                    int blocks) {
  return run<float>(f, blocks);
}
extern "C" __attribute__((noinline)) double hrg_bench_fast_path_f64(const std::vector<q31_t>& f,
                                                                    int blocks) {
  return run<double>(f, blocks);
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: %s q31|f32|f64|chain_q31|chain_f32|chain_q31_cal|chain_f32_cal BLOCKS\n",
                 argv[0]);
    return 2;
  }
  const int blocks = std::atoi(argv[2]);
  std::vector<q31_t> frames(2 * kL);
  for (uint32_t n = 0; n < kL; ++n) {
    frames[2 * n] = q31_from_f64_sat(0.5 * std::cos(0.1 * std::numbers::pi * n));
    frames[2 * n + 1] = q31_from_f64_sat(0.1 * std::cos(0.1 * std::numbers::pi * n + 0.3));
  }
  double r = 0.0;
  if (std::strcmp(argv[1], "q31") == 0) {
    r = hrg_bench_fast_path_q31(frames, blocks);
  } else if (std::strcmp(argv[1], "f32") == 0) {
    r = hrg_bench_fast_path_f32(frames, blocks);
  } else if (std::strcmp(argv[1], "f64") == 0) {
    r = hrg_bench_fast_path_f64(frames, blocks);
  } else if (std::strcmp(argv[1], "chain_q31") == 0) {
    r = hrg_bench_chain_q31(frames, blocks);
  } else if (std::strcmp(argv[1], "chain_f32") == 0) {
    r = hrg_bench_chain_f32(frames, blocks);
  } else if (std::strcmp(argv[1], "chain_q31_cal") == 0) {
    r = hrg_bench_chain_q31_cal(frames, blocks);
  } else if (std::strcmp(argv[1], "chain_f32_cal") == 0) {
    r = hrg_bench_chain_f32_cal(frames, blocks);
  } else {
    std::fprintf(
        stderr,
        "unknown mode '%s' (q31, f32, f64, chain_q31, chain_f32, chain_q31_cal, chain_f32_cal)\n",
        argv[1]);
    return 2;
  }
  std::printf("%s: %d blocks of %u frames, checksum %.9f\n", argv[1], blocks, kL, r);
  return 0;
}
