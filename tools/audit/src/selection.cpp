// SPDX-License-Identifier: MIT
// The effective sample count of a model's residuals and the locations of
// what it leaves in them; the switching edges' feedthrough statistic is in
// feedthrough_edges.cpp.
#include "selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

#include <Eigen/Dense>

#include "dsp/wave_variables.hpp"
#include "number_text.hpp"

namespace hrg::audit::detail {

namespace {

constexpr double kPi = std::numbers::pi;

// The input rate a free decay saw: the recording's, or, without a rate_dps
// column, the pattern's own measured turn. The model then holds the pattern
// still, and a turn well beyond the angle noise is misfit for that alone.
std::string rate_note(const Dataset& d, const FreeSegment& s) {
  const Block& first = d.blocks[s.first_block];
  if (d.has_rate) return fmt(" (mean |rate| %.3g deg/s)", std::abs(first.rate_rad_s) * 180.0 / kPi);
  const Block& last = d.blocks[s.first_block + s.n_blocks - 1];
  if (!(last.t_s > first.t_s) || !(first.a2_v2 > 0.0)) return "";
  const double turn_rad = last.theta_rad - first.theta_rad;
  const double angle_noise_rad = d.noise_v / std::sqrt(first.a2_v2);
  const bool significant = std::abs(turn_rad) > 20.0 * angle_noise_rad;
  return fmt(" (no rate_dps column; the pattern turns at %.3g deg/s there",
             turn_rad / (last.t_s - first.t_s) * 180.0 / kPi) +
         (significant ? ", which the model holds still: add the input rate)" : ")");
}

}  // namespace

double effective_fraction(const std::vector<double>& res, std::size_t n_free_res) {
  // Integrated autocorrelation time of the block residuals (lags in blocks,
  // 4 residuals per block), summed over pairs of lags while the pair sum stays
  // positive: slow coloured noise (1/f-like) keeps the correlation up over
  // many blocks, and its samples count for less than white ones. For an AR(1)
  // residual this is (1 - rho)/(1 + rho).
  n_free_res = std::min(n_free_res, res.size());
  double den = 0.0;
  for (std::size_t i = 0; i < n_free_res; ++i)
    den += res[i] * res[i];
  if (den <= 0.0) return 1.0;
  auto rho = [&](std::size_t lag) {
    double num = 0.0;
    for (std::size_t i = 0; i + 4 * lag < n_free_res; ++i)
      num += res[i] * res[i + 4 * lag];
    return num / den;
  };
  const std::size_t max_lag = std::min<std::size_t>(64, n_free_res / 40);
  double tau = 1.0;
  const double r1 = rho(1);
  if (r1 <= 0.0) return 1.0;
  tau += 2.0 * r1;
  for (std::size_t lag = 2; lag + 1 <= max_lag; lag += 2) {
    const double pair = rho(lag) + rho(lag + 1);
    if (pair <= 0.0) break;
    tau += 2.0 * pair;
  }
  return std::clamp(1.0 / tau, 0.02, 1.0);
}

namespace {

// Free segments whose excess chi^2 over their degrees of freedom stands out
// (up to three, above 5 sigma).
void locate_segments(const Dataset& d, const std::vector<double>& res, std::vector<Location>& out) {
  struct SegScore {
    double excess;
    std::size_t i;
  };
  std::vector<SegScore> segs;
  std::size_t k = 0;
  for (std::size_t si = 0; si < d.free.size(); ++si) {
    const auto& s = d.free[si];
    double chi = 0.0;
    for (std::size_t b = 0; b < s.n_blocks && k + 3 < res.size(); ++b, k += 4) {
      chi += res[k] * res[k] + res[k + 1] * res[k + 1] + res[k + 2] * res[k + 2] +
             res[k + 3] * res[k + 3];
    }
    segs.push_back({chi - 4.0 * static_cast<double>(s.n_blocks), si});
  }
  std::sort(segs.begin(), segs.end(), [](auto a, auto b) { return a.excess > b.excess; });
  for (std::size_t i = 0; i < std::min<std::size_t>(3, segs.size()); ++i) {
    const auto& s = d.free[segs[i].i];
    const double z = segs[i].excess / std::sqrt(8.0 * static_cast<double>(s.n_blocks));
    if (z < 5.0) break;
    out.push_back({"cx_v,sx_v,cy_v,sy_v",
                   fmt("free decay %.2f-%.2f s", s.t0_s, s.t1_s) + rate_note(d, s),
                   segs[i].excess});
  }
}

// Normal equations of a fit on {1, cos 4theta, sin 4theta}.
struct Harmonic3 {
  double s[3][3] = {};
  double y[3] = {};
  void add(const double f[3], double v) {
    for (int i = 0; i < 3; ++i) {
      y[i] += f[i] * v;
      for (int j = 0; j < 3; ++j)
        s[i][j] += f[i] * f[j];
    }
  }
  // chi^2 explained by the 4-theta harmonic beyond the mean, and its cos/sin.
  std::array<double, 3> solve() const {
    Eigen::Matrix3d a;
    Eigen::Vector3d b;
    for (int i = 0; i < 3; ++i) {
      b(i) = y[i];
      for (int j = 0; j < 3; ++j)
        a(i, j) = s[i][j];
    }
    if (std::abs(a.determinant()) < 1e-9 * std::pow(a(0, 0), 3)) return std::array<double, 3>{};
    const Eigen::Vector3d c = a.ldlt().solve(b);
    const double explained = b.dot(c) - y[0] * y[0] / std::max(s[0][0], 1e-30);
    return std::array<double, 3>{explained, c(1), c(2)};
  }
};

// 4-theta harmonics of the amplitude and quadrature residuals.
void locate_harmonics(const Dataset& d, const Params& p, const std::vector<double>& res,
                      std::vector<Location>& out) {
  Harmonic3 ha, hq;
  std::vector<std::array<cplx, 2>> pred;
  std::vector<double> tmp;
  evaluate(d, p, EvalOptions{}, tmp, &pred);
  std::size_t k = 0;
  for (const auto& s : d.free) {
    for (std::size_t b = 0; b < s.n_blocks && k + 3 < res.size(); ++b, k += 4) {
      const Block& bl = d.blocks[s.first_block + b];
      const auto& pr = pred[s.first_block + b];
      const auto wm =
          dsp::wave_variables<double>({bl.x.real(), -bl.x.imag(), bl.y.real(), -bl.y.imag()});
      const auto wp =
          dsp::wave_variables<double>({pr[0].real(), -pr[0].imag(), pr[1].real(), -pr[1].imag()});
      const double sig = d.noise_v / std::sqrt(bl.n);
      const double f[3] = {1.0, std::cos(4.0 * bl.theta_rad), std::sin(4.0 * bl.theta_rad)};
      ha.add(f, (wm.a_A_v - wp.a_A_v) / sig);
      hq.add(f, (wm.a_B_v - wp.a_B_v) / sig);
    }
  }
  const struct {
    std::array<double, 3> h;
    const char* signal;
    const char* what;
  } parts[] = {{ha.solve(), "a_A (measured amplitude)", "amplitude"},
               {hq.solve(), "a_B (quadrature)", "quadrature"}};
  for (const auto& part : parts) {
    if (part.h[0] <= 25.0) continue;
    const double amp = std::hypot(part.h[1], part.h[2]);
    out.push_back({part.signal,
                   std::string("4-theta harmonic of the ") + part.what +
                       fmt(" residual, %.3g V at 4theta = %.0f deg", amp * d.noise_v,
                           std::atan2(part.h[2], part.h[1]) * 180.0 / kPi),
                   part.h[0]});
  }
}

// Excitation segments: mean frequency offset while the pump is on.
void locate_forced(const Dataset& d, const Params& p, std::vector<Location>& out) {
  const ForcedOffset o = forced_offset(d, p);
  const double z = o.mean_rad_s / o.sigma_rad_s;
  if (z * z > 25.0) {
    out.push_back({"wave frequency",
                   fmt("excitation segments (pump on, mean pump_v^2 %.3g V^2): %.3g mHz "
                       "off the free-decay frequency",
                       o.mean_v2, o.mean_rad_s / (2.0 * kPi) * 1e3),
                   z * z});
  }
}

}  // namespace

ForcedOffset forced_offset(const Dataset& d, const Params& p) {
  const auto fr = forced_residuals(d, p);
  ForcedOffset o;
  double wsum = 0.0;
  for (std::size_t i = 0; i < fr.size(); ++i) {
    const double w = 1.0 / (d.forced[i].sigma_rad_s * d.forced[i].sigma_rad_s);
    o.mean_rad_s += w * fr[i], o.mean_v2 += d.forced[i].mean_v2 / static_cast<double>(fr.size());
    wsum += w;
  }
  if (wsum > 0.0) {
    o.mean_rad_s /= wsum;
    o.sigma_rad_s = 1.0 / std::sqrt(wsum);
  }
  return o;
}

std::vector<Location> locate(const Dataset& d, const Params& p, const std::vector<double>& res,
                             bool use_forced, const FeedStat& ft) {
  std::vector<Location> out;
  locate_segments(d, res, out);
  locate_harmonics(d, p, res, out);
  if (use_forced && !d.forced.empty()) locate_forced(d, p, out);
  if (ft.testable && ft.dchi2 > 25.0) {
    out.push_back({"cx_v,sx_v,cy_v,sy_v",
                   fmt("switching instants of exc (%.0f edges): steps of %.3g V/V of pump "
                       "voltage",
                       ft.edges, std::max(ft.c_x, ft.c_y)),
                   ft.dchi2});
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.score > b.score; });
  return out;
}

}  // namespace hrg::audit::detail
