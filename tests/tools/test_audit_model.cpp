// SPDX-License-Identifier: MIT
// Unit checks of the audit's model pieces and its input handling (fast).
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "audit/audit.hpp"
#include "audit/audit_command.hpp"
#include "../../tools/audit/src/model.hpp"

#include "support/cpputest.hpp"

using hrg::audit::detail::cplx;
using hrg::audit::detail::expm2;
using hrg::audit::detail::Mat2;

namespace {

// exp(A t) by its Taylor series (converges for the small |A t| used here).
Mat2 expm_series(const Mat2& a, double t) {
  Mat2 sum{1.0, 0.0, 0.0, 1.0}, term{1.0, 0.0, 0.0, 1.0};
  for (int k = 1; k < 40; ++k) {
    const Mat2 prev = term;
    term = {(prev[0] * a[0] + prev[1] * a[2]) * t / static_cast<double>(k),
            (prev[0] * a[1] + prev[1] * a[3]) * t / static_cast<double>(k),
            (prev[2] * a[0] + prev[3] * a[2]) * t / static_cast<double>(k),
            (prev[2] * a[1] + prev[3] * a[3]) * t / static_cast<double>(k)};
    for (int i = 0; i < 4; ++i)
      sum[static_cast<std::size_t>(i)] += term[static_cast<std::size_t>(i)];
  }
  return sum;
}

std::string write_temp(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::temp_directory_path() / ("hrg_test_audit_" + name);
  std::ofstream(p) << text;
  return p.string();
}

int run_audit_cli(std::vector<std::string> args) {
  std::vector<char*> argv;
  for (auto& a : args)
    argv.push_back(a.data());
  return hrg::audit::audit_main(std::span<char* const>(argv.data(), argv.size()));
}

}  // namespace

TEST_GROUP(AuditPropagator){};

TEST(AuditPropagator, ClosedFormMatchesTheSeries) {
  // GIVEN the averaged-model matrix of a resonator with damping 3e-3 1/s,
  // anisotropy, a half split of 2e-3 rad/s and 10 deg/s of rate (K = 0.554)
  const double ok = 10.0 * M_PI / 180.0 * 0.554;
  const Mat2 a{cplx(-3.1e-3, 2.3e-3), cplx(-1e-4, 5e-4) + ok, cplx(-1e-4, 5e-4) - ok,
               cplx(-2.9e-3, -1.7e-3)};
  for (double t : {0.005, 0.5, 5.0}) {
    const Mat2 e = expm2(a, t);
    const Mat2 s = expm_series(a, t);
    for (int i = 0; i < 4; ++i) {
      CHECK(std::abs(e[static_cast<std::size_t>(i)] - s[static_cast<std::size_t>(i)]) < 1e-12);
    }
  }
}

TEST(AuditPropagator, PureRateRotatesThePatternAtMinusKOmegaOverTwo) {
  // theta_A' = -K Omega / 2 (physics.md section 1): 2 theta turns by -K Omega t.
  const double omega = 0.3, k = 0.554, t = 2.0;
  const Mat2 a{0.0, omega * k, -omega * k, 0.0};
  const Mat2 e = expm2(a, t);
  // Start with the pattern at 0 (X = 1, Y = 0); Y/X = tan(2 theta).
  const double two_theta = std::atan2(e[2].real(), e[0].real());
  DOUBLES_EQUAL(-k * omega * t, two_theta, 1e-12);
}

TEST_GROUP(AuditInput){};

TEST(AuditInput, MalformedRecordingIsRefusedWithLineAndColumn) {
  const std::string p = write_temp("bad.csv",
                                   "# hrg-recording v1\n# f_ref_hz=5000\n# angular_gain=0.554\n"
                                   "t_s,cx_v,sx_v,cy_v,sy_v,exc\n0.005,1,0,0,0,0\n"
                                   "0.010,1,zero,0,0,0\n");
  LONGS_EQUAL(1, run_audit_cli({p}));
  std::filesystem::remove(p);
}

TEST(AuditInput, RecordingWithoutFreeDecayIsRefused) {
  std::string text =
      "# hrg-recording v1\n# f_ref_hz=5000\n# angular_gain=0.554\n"
      "t_s,cx_v,sx_v,cy_v,sy_v,exc\n";
  for (int i = 1; i <= 50; ++i)
    text += std::to_string(0.005 * i) + ",1,0,0,0,1\n";
  const std::string p = write_temp("forced.csv", text);
  LONGS_EQUAL(1, run_audit_cli({p}));
  std::filesystem::remove(p);
}

TEST(AuditInput, UsageErrorsReturnTwo) {
  LONGS_EQUAL(2, run_audit_cli({}));
  LONGS_EQUAL(2, run_audit_cli({"a.csv", "--bogus"}));
}
