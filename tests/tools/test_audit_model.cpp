// SPDX-License-Identifier: MIT
// Unit checks of the audit's model pieces and its input handling (fast).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "audit/audit.hpp"
#include "audit/audit_command.hpp"
#include "../../tools/audit/src/model.hpp"
#include "../../tools/audit/src/noise_model.hpp"

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

// A free decay of the exact averaged Duffing resonator (the cubic force
// -kappa (x^2 + y^2) [x, y] averaged over a cycle, physics.md and
// docs/effects-catalog.md): Z' = A Z + i (4/3) 2 pi c (|Z|^2 Z / 2 + (X^2 +
// Y^2) conj(Z) / 4), A = i dw [c4w s4w; s4w -c4w] - nu I, a standing vibration of
// 1 V at theta 0, by RK4; one row of the audit's blocks every 10 ms.
hrg::audit::detail::Dataset exact_duffing_decay(double c_hz_per_v2, double dw_c, double dw_s,
                                                double nu, double t_end_s) {
  using std::numbers::pi;
  const cplx i(0.0, 1.0);
  auto rhs = [&](const std::array<cplx, 2>& z) {
    const double p2 = std::norm(z[0]) + std::norm(z[1]);
    const cplx w2 = z[0] * z[0] + z[1] * z[1];
    const cplx k = i * (4.0 / 3.0) * 2.0 * pi * c_hz_per_v2;
    return std::array<cplx, 2>{i * (dw_c * z[0] + dw_s * z[1]) - nu * z[0] +
                                   k * (0.5 * p2 * z[0] + 0.25 * w2 * std::conj(z[0])),
                               i * (dw_s * z[0] - dw_c * z[1]) - nu * z[1] +
                                   k * (0.5 * p2 * z[1] + 0.25 * w2 * std::conj(z[1]))};
  };
  hrg::audit::detail::Dataset d;
  d.f_ref_hz = 4200.0, d.angular_gain = 0.554, d.noise_v = 1.0, d.temp_ref_c = 25.0;
  std::array<cplx, 2> z{1.0, 0.0};
  const double h = 1e-3;
  for (int step = 0; step <= static_cast<int>(t_end_s / h + 0.5); ++step) {
    if (step % 10 == 0) {
      hrg::audit::detail::Block b;
      b.t_s = step * h, b.n = 1.0, b.x = z[0], b.y = z[1], b.rot = 1.0, b.temp_c = 25.0;
      const double q = -2.0 * (std::conj(z[0]) * z[1]).imag();  // 2 a_A a_B
      const double e = std::norm(z[0]) + std::norm(z[1]);
      b.a2_v2 = 0.5 * (e + std::sqrt(std::max(0.0, e * e - q * q)));  // a_A^2
      d.blocks.push_back(b);
    }
    auto add = [](const std::array<cplx, 2>& a, const std::array<cplx, 2>& k, double f) {
      return std::array<cplx, 2>{a[0] + f * k[0], a[1] + f * k[1]};
    };
    const auto k1 = rhs(z), k2 = rhs(add(z, k1, h / 2)), k3 = rhs(add(z, k2, h / 2)),
               k4 = rhs(add(z, k3, h));
    for (int m = 0; m < 2; ++m)
      z[m] += h / 6.0 * (k1[m] + 2.0 * k2[m] + 2.0 * k3[m] + k4[m]);
  }
  d.free.push_back({0, d.blocks.size(), 0, 0, 0.0, t_end_s, false});
  return d;
}

// The rms of the model's residual (V) over a dataset at parameters p.
double model_rms_v(const hrg::audit::detail::Dataset& d, const hrg::audit::detail::Params& p) {
  std::vector<double> r;
  hrg::audit::detail::evaluate(d, p, {}, r);
  double s = 0.0;
  for (double v : r)
    s += v * v;
  return std::sqrt(s / static_cast<double>(r.size()));
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

TEST(AuditPropagator, ADuffingTermTurnsThePatternThroughTheQuadrature) {
  // GIVEN a 2 s free decay of the exact averaged Duffing resonator: c -3e-3
  // Hz/V^2 (the Gregory variant), a split of 1.2 mHz at -20 deg (the other
  // resonator's: dw = 2 pi 0.6e-3 rad/s), nu 1.65e-3 1/s; the split grows the
  // quadrature a_B, and the cubic force acts on it at a third of its action
  // on a_A, so the pattern turns at 2 theta' = -(2/3) 2 pi c a_A a_B
  using namespace hrg::audit::detail;
  const double dw = 2.0 * std::numbers::pi * 0.6e-3, th4 = 4.0 * (-20.0) * std::numbers::pi / 180.0;
  const Dataset d =
      exact_duffing_decay(-3e-3, dw * std::cos(th4), dw * std::sin(th4), 1.65e-3, 2.0);
  Params p{};
  p[kNu] = 1.65e-3, p[kDwC] = dw * std::cos(th4), p[kDwS] = dw * std::sin(th4), p[kK] = 0.554;
  p[kDuff] = -3e-3;
  // WHEN the audit's model is evaluated at the truth (its initial state fitted)
  const double rms = model_rms_v(d, p);
  // THEN it follows the decay to 9.8e-8 V rms (what is left is second order
  // in a_B / a_A, 7e-3 at the end); with the isotropic frequency shift alone
  // (before) it left 1.39e-5 V, and 5e-13 V either way without the split
  std::printf("\nDuffing decay: model rms %.3g V\n", rms);
  CHECK(rms < 2e-7);
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

TEST_GROUP(AuditNoiseModel){};

TEST(AuditNoiseModel, ArModelWhitensAnAr1ResidualAndLeavesWhiteNoiseAlone) {
  // GIVEN residuals of 20 free segments of 400 blocks (4 channels per block):
  // channel 0 an AR(1) process r_t = 0.9 r_{t-1} + e_t with var(e) = 0.25,
  // the other channels white with unit variance
  hrg::audit::detail::Dataset d;
  std::mt19937_64 g(7);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> res;
  for (int s = 0; s < 20; ++s) {
    hrg::audit::detail::FreeSegment seg;
    seg.first_block = static_cast<std::size_t>(s) * 400;
    seg.n_blocks = 400;
    d.free.push_back(seg);
    double ar = n(g) * 0.5 / std::sqrt(1.0 - 0.81);  // stationary start
    for (int b = 0; b < 400; ++b) {
      ar = 0.9 * ar + 0.5 * n(g);
      res.push_back(ar);
      for (int c = 1; c < 4; ++c)
        res.push_back(n(g));
    }
  }
  // WHEN the AR noise model is fitted
  const auto m = hrg::audit::detail::fit_ar_noise(d, res);
  // THEN channel 0 gets order 1 (BIC) with a_1 = 0.9 and var(e) = 0.25 to a
  // few standard errors (sd of a_1 = sqrt((1 - 0.81)/8000) = 0.005), and the
  // white channels order 0 with unit variance (sd sqrt(2/8000) = 0.016)
  CHECK_EQUAL(1, m.order(0));
  DOUBLES_EQUAL(0.9, m.orders[0][1].coef[0], 0.02);
  DOUBLES_EQUAL(0.25, m.orders[0][1].var, 0.25 * 0.06);
  for (std::size_t c = 1; c < 4; ++c) {
    CHECK_EQUAL(0, m.order(c));
    DOUBLES_EQUAL(1.0, m.orders[c][0].var, 0.06);
  }
  // AND the whitened chi^2 is about its count (32000 +- 4 sd of 253), while
  // the raw one is inflated by the AR channel's variance 0.25/0.19 = 1.32
  const double chi2_w = hrg::audit::detail::whitened_chi2(d, res, m);
  DOUBLES_EQUAL(32000.0, chi2_w, 1000.0);
  double raw = 0.0;
  for (double v : res)
    raw += v * v;
  CHECK(raw > chi2_w + 0.2 * 8000.0);
}

TEST(AuditNoiseModel, NoiseSlowerThanTheArModelIsHeldByItsScales) {
  // GIVEN residuals of 8 free segments of 2048 blocks: on the x pickoff
  // (channels 0-1) unit white noise plus 1/f-like noise, ten first-order
  // processes of variance 0.1 with corners doubling from 1/4096 to 1/8 per
  // block (density ~ 1/f between them), on the y pickoff unit white noise
  hrg::audit::detail::Dataset d;
  std::mt19937_64 g(11);
  std::normal_distribution<double> n(0.0, 1.0);
  constexpr int kBlocks = 2048;
  std::vector<double> res;
  for (int s = 0; s < 8; ++s) {
    hrg::audit::detail::FreeSegment seg;
    seg.first_block = static_cast<std::size_t>(s) * kBlocks;
    seg.n_blocks = kBlocks;
    d.free.push_back(seg);
    std::array<std::array<double, 10>, 2> slow{};
    for (auto& ch : slow)
      for (double& x : ch)
        x = std::sqrt(0.1) * n(g);
    for (int b = 0; b < kBlocks; ++b) {
      for (std::size_t c = 0; c < 4; ++c) {
        double v = n(g);
        for (std::size_t o = 0; c < 2 && o < 10; ++o) {
          const double a =
              std::exp(-2.0 * std::numbers::pi * std::ldexp(1.0, -12 + static_cast<int>(o)));
          slow[c][o] = a * slow[c][o] + std::sqrt(0.1 * (1.0 - a * a)) * n(g);
          v += slow[c][o];
        }
        res.push_back(v);
      }
    }
  }
  // WHEN the noise model is fitted
  const auto m = hrg::audit::detail::fit_ar_noise(d, res);
  // THEN the white pickoff's scales stay at the white level 1, and the 1/f
  // pickoff's grow at the coarse ones (above 3x at 1024 blocks)
  for (std::size_t j = 1; j <= hrg::audit::detail::ArNoise::kScales; ++j)
    DOUBLES_EQUAL(1.0, m.scale_var[1][j], 0.0);
  CHECK(m.scale_var[0][10] > 3.0);
  // AND a slow structure (a parabola over each segment, raw chi^2 D; alone,
  // the whitening being linear in the residuals) counts about D on the
  // white pickoff (its innovation variance 1 to a few 0.016) and less than
  // half of what the AR whitening alone counts on the 1/f pickoff: there
  // most of it stands within the slow noise
  auto parabola = [&](std::size_t channel, double& raw) {
    std::vector<double> r(res.size(), 0.0);
    raw = 0.0;
    for (std::size_t s = 0; s < d.free.size(); ++s) {
      for (int b = 0; b < kBlocks; ++b) {
        const double u = 2.0 * b / (kBlocks - 1.0) - 1.0;
        const double q = 0.35 * (u * u - 1.0 / 3.0);
        r[4 * (s * kBlocks + static_cast<std::size_t>(b)) + channel] = q;
        raw += q * q;
      }
    }
    return r;
  };
  double dy = 0.0, dx = 0.0;
  const auto qy = parabola(2, dy);
  const auto qx = parabola(0, dx);
  DOUBLES_EQUAL(dy, hrg::audit::detail::whitened_chi2(d, qy, m), 0.1 * dy);
  auto ar_only = m;
  for (auto& v : ar_only.scale_var)
    v.fill(1.0);
  const double count_x = hrg::audit::detail::whitened_chi2(d, qx, m);
  const double count_x_ar = hrg::audit::detail::whitened_chi2(d, qx, ar_only);
  CHECK_TEXT(count_x < 0.5 * count_x_ar,
             (std::to_string(count_x) + " vs " + std::to_string(count_x_ar)).c_str());
}
