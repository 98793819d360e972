// SPDX-License-Identifier: MIT
// Writes the data sheet JSON of series whose answers are known (the inputs of
// the characterization tests), for the render check of report.html.
// Usage: characterize_datasheet_demo OUT.json
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <random>
#include <vector>

#include "characterize/datasheet.hpp"
#include "characterize/whole_angle_limits.hpp"
#include "noise_synth.hpp"

using namespace hrg::characterize;

namespace {
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr double kDphPerRadS = 180.0 / std::numbers::pi * 3600.0;

void add_noise(DataSheet& sheet) {
  // ARW 0.005 deg/sqrt(h), B 0.05 deg/h, K 0.1 deg/h/sqrt(h), 1 Hz for 145 h.
  const std::size_t n = 1 << 19;
  auto y = hrg::testing::white_series(n, 0.005 * kRadPerDeg / 60.0, 21);
  const double b = 0.05 * kRadPerDeg / 3600.0, k = 0.1 * kRadPerDeg / 3600.0 / 60.0;
  const auto f = hrg::testing::kasdin_series(n, 1.0, b * b, 22);
  const auto r = hrg::testing::random_walk_series(n, k, 23);
  for (std::size_t i = 0; i < n; ++i)
    y[i] += f[i] + r[i];
  AllanOptions o;
  o.confidence = 0.95;
  const auto curve = allan_from_rate(y, 1.0, o);
  sheet.noise(curve, noise_terms(curve), o.confidence);
}

void add_scale_factor(DataSheet& sheet) {
  // K = 1 + 150 ppm, asymmetry 80 ppm, steps read to 1e-4 deg/s; a 1 % pickoff gain mismatch.
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g(0.0, 1e-4 * kRadPerDeg);
  std::vector<RateStep> steps;
  for (const double d : {5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 300.0})
    for (const double sign : {1.0, -1.0}) {
      const double in = sign * d * kRadPerDeg;
      steps.push_back({in, 1.000150 * (1.0 + 40e-6 * sign) * in + g(rng), 1e-4 * kRadPerDeg});
    }
  std::vector<double> truth, readout;
  for (int i = 0; i < 720; ++i) {
    const double th = i * kRadPerDeg;
    double rd = 0.5 * std::atan2(std::sin(2 * th), 1.01 * std::cos(2 * th));
    rd += std::round((th - rd) / std::numbers::pi) * std::numbers::pi;
    truth.push_back(th);
    readout.push_back(rd);
  }
  sheet.scale_factor(steps, analyze_scale_factor(steps), truth, readout,
                     analyze_angle_readout(truth, readout));
}

void add_drift(DataSheet& sheet) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> g(0.0, 0.5);
  std::vector<double> turn_on, temp, bias;
  for (int i = 0; i < 12; ++i)
    turn_on.push_back(3.0 + g(rng));
  for (double t = -40; t <= 80; t += 10) {
    temp.push_back(t);
    bias.push_back(3.0 + 0.02 * t + 0.1 * g(rng));
  }
  sheet.drift(turn_on, bias_repeatability(turn_on), temp, bias, bias_temperature_slope(temp, bias));
}

void add_limits(DataSheet& sheet) {
  // The seed's example resonator: f 5 kHz, Q 5e6, dmu 0.05, K 0.554; 90 % of dmu identified.
  const double nu = damping_rate_per_s(5000.0, 5e6);
  DataSheet::Limits l;
  l.threshold_raw_dph = rate_threshold_rad_s(nu, 0.05, 0.554) * kDphPerRadS;
  l.threshold_compensated_dph = rate_threshold_rad_s(nu, 0.005, 0.554) * kDphPerRadS;
  l.rundown_s = rundown_time_s(1.0, 1e-4, nu, 0.05, std::numbers::pi / 8, 0.0);
  l.note = "closed form for the seed resonator (Q 5e6, dmu 0.05)";
  sheet.limits(l);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT.json\n", argv[0]);
    return 2;
  }
  DataSheet sheet("Data sheet of known inputs (characterization self-check)");
  add_noise(sheet);
  add_scale_factor(sheet);
  add_drift(sheet);
  add_limits(sheet);
  std::ofstream out(argv[1]);
  out << sheet.finish();
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  return 0;
}
