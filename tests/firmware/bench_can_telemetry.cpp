// SPDX-License-Identifier: MIT
// Cost of the CAN telemetry encoder (fw::can::TelemetryEncoder::tick) per
// base frame, for instruction counting under callgrind
// (bench_can_telemetry.cmake): `all` the default rates, `no_readings` the
// same without HRG_CAL_READINGS (the difference is what the firmware's
// readings cost per frame in the encoder); `referral` one call of what
// fw::app::Firmware::estimates() adds to a copy, the residual referred to the
// raw pickoffs (once per set of readings, every 700 frames at the default
// rate). Without valgrind it just runs and prints a checksum.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/calibration.hpp"
#include "firmware/can/telemetry.hpp"

using namespace hrg::fw::can;

namespace {

TelemetrySnapshot snapshot(int k) {
  TelemetrySnapshot s;
  s.cx_v = 0.8 + 1e-6 * k;
  s.sy_v = -0.02;
  s.row_t_s = 1e-3 * k;
  s.f_ref_hz = 5000.0;
  s.pll_freq_hz = 5000.01;
  s.estimates.feedthrough = true;
  s.estimates.edges = 34;
  s.estimates.feedthrough_residual_v_per_v = {4e-4, 6.9e-4, 6.9e-4, -4e-4};
  s.estimates.feedthrough_sigma_v_per_v = 2.7e-6;
  s.estimates.thermal_damping = true;
  s.estimates.thermal_damping_per_c = 0.0039;
  return s;
}

}  // namespace

extern "C" __attribute__((noinline)) double hrg_bench_can_tick(int frames, bool readings) {
  TelemetryConfig c = TelemetryConfig::defaults();
  if (!readings) c.rate_hz[static_cast<std::size_t>(Tm::cal_readings)] = 0;
  TelemetryEncoder enc(c, 1000);
  std::array<hrg::hal::CanFrame, kTelemetryCount> out{};
  double sum = 0;
  for (int k = 0; k < frames; ++k) {
    const std::size_t n = enc.tick(snapshot(k), out);
    for (std::size_t j = 0; j < n; ++j)
      sum += out[j].data[j % 8];
  }
  return sum;
}

extern "C" __attribute__((noinline)) double hrg_bench_referral(int calls) {
  hrg::fw::Calibration cal;
  cal.pickoff_y_gain = -0.01;
  cal.pickoff_y_phase_rad = 0.002;
  cal.pickoff_y_misalignment_rad = 0.001;
  double sum = 0;
  for (int k = 0; k < calls; ++k) {
    const auto r = hrg::fw::residual_at_raw_pickoffs(cal, {4e-4, 6.9e-4, 6.9e-4 + 1e-9 * k, -4e-4});
    sum += r.y_re + r.y_im;
  }
  return sum;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s all|no_readings|referral N\n", argv[0]);
    return 2;
  }
  const int n = std::atoi(argv[2]);
  double v = 0;
  if (std::strcmp(argv[1], "all") == 0) {
    v = hrg_bench_can_tick(n, true);
  } else if (std::strcmp(argv[1], "no_readings") == 0) {
    v = hrg_bench_can_tick(n, false);
  } else if (std::strcmp(argv[1], "referral") == 0) {
    v = hrg_bench_referral(n);
  } else {
    std::fprintf(stderr, "unknown mode '%s'\n", argv[1]);
    return 2;
  }
  std::printf("%s: %d, checksum %.9g\n", argv[1], n, v);
  return 0;
}
