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
// excitation on so every part runs.
template <typename T>
double run_chain(const std::vector<q31_t>& frames, int blocks) {
  ChainConfig cfg;
  cfg.f_center_hz = 5000.2;
  static Chain<T> chain(cfg);
  chain.reset();
  chain.set_excitation(true);
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
  return run_chain<q31_t>(f, blocks);
}
extern "C" __attribute__((noinline)) double hrg_bench_chain_f32(const std::vector<q31_t>& f,
                                                                int blocks) {
  return run_chain<float>(f, blocks);
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
    std::fprintf(stderr, "usage: %s q31|f32|f64|chain_q31|chain_f32 BLOCKS\n", argv[0]);
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
  } else {
    std::fprintf(stderr, "unknown mode '%s' (q31, f32, f64, chain_q31, chain_f32)\n", argv[1]);
    return 2;
  }
  std::printf("%s: %d blocks of %u frames, checksum %.9f\n", argv[1], blocks, kL, r);
  return 0;
}
