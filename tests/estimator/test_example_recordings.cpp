// SPDX-License-Identifier: MIT
// The estimator on the shared example ring-down recording (hrg-recording v1,
// ../shared/examples): free-decay rows (exc = 0) become windows, the joint
// estimate is compared with the truth file within its own covariance.
#include <estimator/estimator.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <dsp/wave_variables.hpp>

#include "support/cpputest.hpp"

using namespace hrg::est;

namespace {

std::string examples_dir() {
  const char* src = std::getenv("HRG_SOURCE_DIR");
  return std::string(src ? src : ".") + "/../shared/examples/";
}

// Reads "key": number from a flat JSON truth file.
bool truth_value(const std::string& text, const char* key, double& out) {
  const std::string k = std::string("\"") + key + "\"";
  const size_t at = text.find(k);
  if (at == std::string::npos) return false;
  const size_t colon = text.find(':', at);
  if (colon == std::string::npos) return false;
  out = std::strtod(text.c_str() + colon + 1, nullptr);
  return true;
}

std::string read_file(const std::string& path) {
  std::string text;
  FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return text;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0)
    text.append(buf, n);
  std::fclose(f);
  return text;
}

}  // namespace

TEST_GROUP(ExampleRecording){};

TEST(ExampleRecording, JointEstimateOfTheBaselineRingDownMatchesItsTruth) {
  // GIVEN the baseline recording (seed physics only, 200 Hz rows)
  const std::string base = examples_dir() + "ringdown-baseline";
  const std::string truth_text = read_file(base + ".truth.json");
  if (truth_text.empty()) {
    std::printf("\nexample recording not found under %s: skipped\n", examples_dir().c_str());
    return;
  }
  double nu = 0, dmu = 0, th_mu_deg = 0, split_hz = 0, th_w_deg = 0;
  CHECK(truth_value(truth_text, "nu_per_s", nu));
  CHECK(truth_value(truth_text, "dmu", dmu));
  CHECK(truth_value(truth_text, "theta_mu_deg", th_mu_deg));
  CHECK(truth_value(truth_text, "split_hz", split_hz));
  CHECK(truth_value(truth_text, "theta_w_deg", th_w_deg));
  const double th_mu = th_mu_deg * M_PI / 180, th_w = th_w_deg * M_PI / 180;
  ParamVector truth;
  truth << nu, nu * dmu * std::cos(4 * th_mu), nu * dmu * std::sin(4 * th_mu),
      M_PI * split_hz * std::cos(4 * th_w), M_PI * split_hz * std::sin(4 * th_w);

  Estimator::Config cfg;
  cfg.window.max_sample_gap_s = 0.0075;  // 5 ms rows
  Estimator est{cfg};
  const std::string cmd = "gzip -dc '" + base + ".csv.gz'";
  FILE* pipe = popen(cmd.c_str(), "r");
  CHECK(pipe != nullptr);
  char line[512];
  bool header = false, in_window = false;
  int windows = 0, rows = 0;
  while (std::fgets(line, sizeof line, pipe)) {
    if (line[0] == '#') continue;
    if (!header) {
      // The column order of this file; the reader of tools/ handles any order.
      STRCMP_EQUAL("t_s,cx_v,sx_v,cy_v,sy_v,exc,pump_v,temp_c,rate_dps\n", line);
      header = true;
      continue;
    }
    double t, cx, sx, cy, sy;
    int exc;
    if (std::sscanf(line, "%lf,%lf,%lf,%lf,%lf,%d", &t, &cx, &sx, &cy, &sy, &exc) != 6) continue;
    ++rows;
    if (exc == 0 && !in_window) {
      est.begin_window(t - 0.005);  // the switch happened after the previous row
      in_window = true;
    } else if (exc == 1 && in_window) {
      windows += est.end_window() == Status::ok ? 1 : 0;
      in_window = false;
    }
    if (in_window) {
      const auto w = hrg::dsp::wave_variables<double>({cx, sx, cy, sy});
      est.add_sample({t, w.a_A_v, w.a_B_v, w.theta_A_rad, w.E_v2});
    }
  }
  if (in_window) windows += est.end_window() == Status::ok ? 1 : 0;
  pclose(pipe);
  const Solution s = est.solve_and_accept();
  std::printf("\nbaseline recording: %d rows, %d windows, kappa_2 %.2f\n", rows, windows,
              s.cond.kappa_2);
  const char* names[kParams] = {"nu", "dnu_C", "dnu_S", "dw_C", "dw_S"};
  // THEN every parameter is within 4 sigma of its truth
  CHECK(s.accepted());
  for (int i = 0; i < kParams; ++i) {
    const double sigma = std::sqrt(s.covariance(i, i));
    std::printf("  %-6s truth %+.5e estimate %+.5e sigma %.2e (%+.1f sigma)\n", names[i], truth(i),
                s.p(i), sigma, (s.p(i) - truth(i)) / sigma);
    CHECK(std::abs(s.p(i) - truth(i)) < 4 * sigma);
  }
}
