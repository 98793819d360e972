// SPDX-License-Identifier: MIT
// Cost of the electronics corrections per demodulated block (one call each),
// for instruction counting under callgrind (bench_correction.cmake). Without
// valgrind it just runs and prints a checksum.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "dsp/electronics_correction.hpp"
#include "dsp/pickoff_correction.hpp"

using namespace hrg::dsp;

namespace {

PickoffCorrection<double> coefficients() {
  PickoffCorrection<double> k;
  pickoff_correction_of({0.01, 0.017, 0.0087}, k);
  return k;
}

}  // namespace

extern "C" __attribute__((noinline)) double hrg_bench_pickoff_q31(int calls) {
  PickoffCorrectionQ30 k;
  to_q30(coefficients(), k);
  double sum = 0.0;
  for (int i = 0; i < calls; ++i) {
    QuadSample<q31_t> q{i * 977, -i * 131, i * 313, 1 << 29};
    correct_pickoffs_q31(k, q);
    sum += q.cy + q.sy;
  }
  return sum;
}

extern "C" __attribute__((noinline)) double hrg_bench_pickoff_f64(int calls) {
  const PickoffCorrection<double> k = coefficients();
  double sum = 0.0;
  for (int i = 0; i < calls; ++i) {
    Quadratures<double> q{i * 1e-6, -i * 2e-7, 0.3, i * 3e-7};
    correct_pickoffs(k, q);
    sum += q.cy + q.sy;
  }
  return sum;
}

extern "C" __attribute__((noinline)) double hrg_bench_feedthrough_q31(int calls) {
  FeedthroughCoefficients<q31_t> k;
  feedthrough_to_q31({8.66e-4, 5e-4, -2.5e-4, 4.3e-4}, 2.0, 10.0, k);
  double sum = 0.0;
  for (int i = 0; i < calls; ++i) {
    QuadSample<q31_t> q{i * 977, -i * 131, i * 313, 1 << 29};
    remove_feedthrough_q31(k, 1 << 30, i * 1001, q);
    sum += q.cx + q.sy;
  }
  return sum;
}

extern "C" __attribute__((noinline)) double hrg_bench_feedthrough_f64(int calls) {
  const FeedthroughCoefficients<double> k{8.66e-4, 5e-4, -2.5e-4, 4.3e-4};
  double sum = 0.0;
  for (int i = 0; i < calls; ++i) {
    Quadratures<double> q{i * 1e-6, -i * 2e-7, 0.3, i * 3e-7};
    remove_feedthrough(k, 5.0, i * 1e-3, q);
    sum += q.cx + q.sy;
  }
  return sum;
}

// The chain's whole stage (pump envelope filter, feedthrough, pickoff
// inverse) as dsp::Chain runs it once per block.
template <typename T>
double stage(int calls) {
  PumpEnvelopeFilter seen(100);
  ElectronicsCorrection<T> c;
  c.configure(coefficients(), {8.66e-4, 5e-4, -2.5e-4, 4.3e-4}, 2.0, 10.0);
  double sum = 0.0;
  for (int i = 0; i < calls; ++i) {
    QuadSample<T> q{};
    if constexpr (std::is_same_v<T, q31_t>) {
      q = {i * 977, -i * 131, i * 313, 1 << 29};
    } else {
      q = {T(i * 1e-6), T(-i * 2e-7), T(0.3), T(i * 3e-7)};
    }
    double re = 0.0;
    double im = 0.0;
    seen.push(5.0, i * 1e-3, re, im);
    c.apply(re, im, q);
    sum += static_cast<double>(q.cx) + static_cast<double>(q.sy);
  }
  return sum;
}

extern "C" __attribute__((noinline)) double hrg_bench_stage_q31(int calls) {
  return stage<q31_t>(calls);
}

extern "C" __attribute__((noinline)) double hrg_bench_stage_f32(int calls) {
  return stage<float>(calls);
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(
        stderr,
        "usage: %s pickoff_q31|pickoff_f64|feedthrough_q31|feedthrough_f64|stage_q31|stage_f32 N\n",
        argv[0]);
    return 2;
  }
  const int calls = std::atoi(argv[2]);
  double r = 0.0;
  if (std::strcmp(argv[1], "pickoff_q31") == 0) {
    r = hrg_bench_pickoff_q31(calls);
  } else if (std::strcmp(argv[1], "pickoff_f64") == 0) {
    r = hrg_bench_pickoff_f64(calls);
  } else if (std::strcmp(argv[1], "feedthrough_q31") == 0) {
    r = hrg_bench_feedthrough_q31(calls);
  } else if (std::strcmp(argv[1], "feedthrough_f64") == 0) {
    r = hrg_bench_feedthrough_f64(calls);
  } else if (std::strcmp(argv[1], "stage_q31") == 0) {
    r = hrg_bench_stage_q31(calls);
  } else if (std::strcmp(argv[1], "stage_f32") == 0) {
    r = hrg_bench_stage_f32(calls);
  } else {
    std::fprintf(stderr, "unknown mode '%s'\n", argv[1]);
    return 2;
  }
  std::printf("%s: %d calls, checksum %.9g\n", argv[1], calls, r);
  return 0;
}
