// SPDX-License-Identifier: MIT
#include "selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>

#include <Eigen/Dense>

#include "dsp/wave_variables.hpp"

namespace hrg::audit::detail {

namespace {

constexpr double kPi = std::numbers::pi;

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

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

using Vec4 = Eigen::Vector4d;

Vec4 real4(const std::array<cplx, 2>& z) {
  return {z[0].real(), z[0].imag(), z[1].real(), z[1].imag()};
}
std::array<cplx, 2> cplx2(const Vec4& v) { return {cplx(v(0), v(1)), cplx(v(2), v(3))}; }

// One switching edge seen from the free-decay model: the jump J (forced-side
// quadratic extrapolated to the edge, minus the model) with the component
// along the force-driven slope removed (the switching instant within the
// sample interval is not known, so a jump along the slope is not evidence).
struct EdgeJump {
  Vec4 j;                // projected jump (re/im x, re/im y), V
  Eigen::Matrix4d proj;  // projector used
  double var = 0.0;      // noise variance of each real component of j before projection, V^2
  cplx phasor;           // e^{i phi} of the wave at the edge
  double pump_v = 0.0;
  // The pattern angle stands clear of the branch cut of theta_A (+-pi/4),
  // where the wave phase, and with it the pump's, turns by pi: the producer's
  // own measured angle then takes the same branch as the model's.
  bool sign_known = true;
};

// Least distance of the pattern angle from the branch cut of theta_A for an
// edge's sign to follow the wave phase convention: the firmware takes the
// pump's phase from its own measured angle, block by block, which differs
// from the model's at the edge by the rows between them (the table turns the
// pattern by up to 0.15 deg a row), the feedthrough's own pull on the measured
// angle (~0.5 deg at 1e-3 V/V and 10 V of pump) and the pickoff errors.
constexpr double kBranchMarginRad = 2.0 * kPi / 180.0;

// Least share of an edge's mean pump that its fitted pump at the edge keeps.
constexpr double kMinEdgePumpShare = 0.25;
// Most excitation rows with the pump already off before a switch-off that
// still count as that switch-off: a producer that marks a row free only once
// its whole averaging span is leaves a row or two. More, and the pump was
// switched off inside the excitation (an amplitude loop at its lower limit)
// while the forcers still acted: the edge is then neither the pump's switching
// instant nor the start of a free decay, and the free model extrapolated
// back over those rows is no reference for the jump.
constexpr std::size_t kMaxPumpOffRows = 2;

// Slope per pickoff of a straight line through residuals `res` at times
// `tau`. A feedthrough follows each row's pump, so where the pump changes
// over the rows (a switch-on among them, an amplitude loop moving it) the
// line is fitted beside a free term g V per pickoff: the step the pump makes
// there is the feedthrough's, not the force-driven slope's, and taken for
// the slope it would project the feedthrough out of the jump. Empty when
// the rows do not determine a slope.
std::optional<std::array<cplx, 2>> line_slope(const std::vector<double>& tau,
                                              const std::vector<double>& pump_v,
                                              const std::vector<std::array<cplx, 2>>& res) {
  const std::size_t n = tau.size();
  // The pump's part that a line does not hold; below this share of its mean
  // it is a constant, which the line's offset already takes.
  constexpr double kMinPumpChange = 1e-3;
  Eigen::MatrixXd a(n, 3);
  double mean_v = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    a(static_cast<Eigen::Index>(j), 0) = 1.0;
    a(static_cast<Eigen::Index>(j), 1) = tau[j];
    a(static_cast<Eigen::Index>(j), 2) = pump_v.size() == n ? pump_v[j] : 0.0;
    mean_v += a(static_cast<Eigen::Index>(j), 2) / static_cast<double>(n);
  }
  const Eigen::MatrixXd line = a.leftCols(2);
  const Eigen::VectorXd v_left =
      a.col(2) - line * line.colPivHouseholderQr().solve(Eigen::VectorXd(a.col(2)));
  const bool with_pump =
      mean_v > 0.0 && v_left.norm() > kMinPumpChange * mean_v * std::sqrt(static_cast<double>(n));
  const Eigen::MatrixXd m = with_pump ? a : line;
  const Eigen::MatrixXd mtm = m.transpose() * m;
  const Eigen::LDLT<Eigen::MatrixXd> f(mtm);
  if (f.info() != Eigen::Success || !(std::abs(f.vectorD().minCoeff()) > 0.0)) return std::nullopt;
  std::array<cplx, 2> slope{};
  for (std::size_t k = 0; k < 2; ++k) {
    Eigen::VectorXd re(n), im(n);
    for (std::size_t j = 0; j < n; ++j) {
      re(static_cast<Eigen::Index>(j)) = res[j][k].real();
      im(static_cast<Eigen::Index>(j)) = res[j][k].imag();
    }
    const Eigen::VectorXd br = f.solve(m.transpose() * re);
    const Eigen::VectorXd bi = f.solve(m.transpose() * im);
    slope[k] = cplx(br(1), bi(1));
  }
  return slope;
}

EdgeJump edge_jump(const Dataset& d, const Params& p, const Edge& e) {
  EdgeJump ej;
  double phase = 0.0, theta = 0.0;
  std::vector<std::size_t> rows = e.forced_rows;
  rows.insert(rows.end(), e.slope_rows.begin(), e.slope_rows.end());
  const auto pred = predict_rows(d, p, e.free_segment, rows, &phase, &theta);
  ej.sign_known = kPi / 4.0 - std::abs(theta) >= kBranchMarginRad;
  const std::size_t near = e.forced_rows.front();
  const std::size_t free_row = e.at_start ? near + 1 : near - 1;
  const double t_e = 0.5 * (d.t_s[near] + d.t_s[free_row]);
  const double dt = std::abs(d.t_s[near] - d.t_s[free_row]);
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  Eigen::Matrix<cplx, 3, 2> b = Eigen::Matrix<cplx, 3, 2>::Zero();
  Eigen::Vector3d bv = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < e.forced_rows.size(); ++j) {
    const std::size_t row = e.forced_rows[j];
    const double tau = (d.t_s[row] - t_e) / dt;
    const Eigen::Vector3d f(1.0, tau, tau * tau);
    s += f * f.transpose();
    if (!e.forced_pump_v.empty()) bv += f * e.forced_pump_v[j];
    b.row(0) += f(0) * Eigen::RowVector2cd(d.x[row] - pred[j][0], d.y[row] - pred[j][1]);
    b.row(1) += f(1) * Eigen::RowVector2cd(d.x[row] - pred[j][0], d.y[row] - pred[j][1]);
    b.row(2) += f(2) * Eigen::RowVector2cd(d.x[row] - pred[j][0], d.y[row] - pred[j][1]);
  }
  const Eigen::Matrix3d si = s.inverse();
  const Eigen::Matrix<cplx, 3, 2> coef = si.cast<cplx>() * b;
  const Vec4 r0 = real4({coef(0, 0), coef(0, 1)});
  const Vec4 r1 = real4({coef(1, 0), coef(1, 1)});
  // The slope direction from the rows beyond (straight line; independent
  // noise), or from the jump's own rows when the run is too short.
  Vec4 dir = r1;
  if (e.slope_rows.size() >= 8) {
    std::vector<std::array<cplx, 2>> res;
    std::vector<double> tau;
    for (std::size_t j = e.forced_rows.size(); j < rows.size(); ++j) {
      tau.push_back((d.t_s[rows[j]] - t_e) / dt);
      res.push_back({d.x[rows[j]] - pred[j][0], d.y[rows[j]] - pred[j][1]});
    }
    if (const auto slope = line_slope(tau, e.slope_pump_v, res)) dir = real4(*slope);
  }
  ej.proj = Eigen::Matrix4d::Identity();
  if (dir.squaredNorm() > 0.0) ej.proj -= dir * dir.transpose() / dir.squaredNorm();
  ej.j = ej.proj * r0;
  ej.var = si(0, 0) * d.noise_v * d.noise_v;
  ej.phasor = std::polar(1.0, phase);
  // The jump is the rows' fit extrapolated to the edge; a feedthrough in
  // them follows each row's pump, so the pump that goes with the jump is the
  // same fit of the pump column (a steady pump: its mean; a pump that the
  // loop moves from row to row: what is left of it at the edge).
  const double pump_at_edge = e.forced_pump_v.empty() ? e.pump_v : (si * bv)(0);
  ej.pump_v = std::max(pump_at_edge, 1e-12);
  return ej;
}

// Real 4x4 map of c (re/im c_x, re/im c_y) to the edge's feedthrough V e^{i phi} c.
Eigen::Matrix4d feed_map(const EdgeJump& ej) {
  const double a = ej.pump_v * ej.phasor.real(), bb = ej.pump_v * ej.phasor.imag();
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m.block<2, 2>(0, 0) << a, -bb, bb, a;
  m.block<2, 2>(2, 2) << a, -bb, bb, a;
  return ej.proj * m;
}

// A switch-off in the middle of a control transient is not evidence: edges
// far outside the others are dropped (a real feedthrough, proportional to
// the pump voltage, raises all of them together). Returns how many.
int drop_transients(std::vector<EdgeJump>& jumps, std::vector<const Edge*>& used) {
  std::vector<double> q;
  for (const auto& ej : jumps)
    q.push_back(ej.j.squaredNorm() / ej.var);
  std::vector<double> qs(q);
  std::nth_element(qs.begin(), qs.begin() + static_cast<std::ptrdiff_t>(qs.size() / 2), qs.end());
  const double limit = std::max(30.0, 10.0 * qs[qs.size() / 2]);
  std::vector<EdgeJump> kept;
  std::vector<const Edge*> kept_edges;
  for (std::size_t i = 0; i < jumps.size(); ++i) {
    if (q[i] <= limit) kept.push_back(jumps[i]), kept_edges.push_back(used[i]);
  }
  const int dropped = static_cast<int>(jumps.size() - kept.size());
  jumps.swap(kept);
  used.swap(kept_edges);
  return dropped;
}

// Sign-free detection: the mean of w^2 with w = J e^{-i phi} / V per pickoff
// (the vibration's phase is defined modulo pi), minus its noise expectation, each
// edge weighted by the inverse of its term's noise variance (~8 v^2, v the
// edge's noise over V^2). An amplitude loop leaves the pump at a switch-off
// anywhere in its range, and an edge at a fifth of the pump has 625x the
// variance: with equal weights those few edges set the statistic's noise
// (the firmware's telemetry of `audit-bench --seed 2026`, design 2, 31
// switch-offs at 0.67-2.93 V: a feedthrough of 1.66e-5 V/V at 17 sigma of
// its fit gave chi^2 39, delta BIC 3.4). Fills dchi2 and threshold; returns
// the weighted mean of w^2 per pickoff.
std::array<cplx, 2> sign_free_detection(const std::vector<EdgeJump>& jumps, double ln_neff,
                                        FeedStat& fs) {
  std::array<cplx, 2> m{};
  double weights = 0.0;  // sum of 1 / v^2
  for (const auto& ej : jumps) {
    const cplx u = std::conj(ej.phasor) / ej.pump_v;
    const auto z = cplx2(ej.j);
    const double v = ej.var / (ej.pump_v * ej.pump_v);
    const double w_edge = 1.0 / (v * v);
    const Eigen::Matrix4d& pr = ej.proj;
    for (int k = 0; k < 2; ++k) {
      const cplx w = z[static_cast<std::size_t>(k)] * u;
      const cplx bias =
          v * cplx(pr(2 * k, 2 * k) - pr(2 * k + 1, 2 * k + 1), 2.0 * pr(2 * k, 2 * k + 1)) *
          std::conj(ej.phasor * ej.phasor);
      m[static_cast<std::size_t>(k)] += w_edge * (w * w - bias);
    }
    weights += w_edge;
  }
  for (auto& mk : m)
    mk /= weights;
  const double var_m = 8.0 / weights;
  fs.dchi2 = 2.0 * (std::norm(m[0]) + std::norm(m[1])) / var_m;
  // |c| at which the expected delta BIC is zero: 2 |c|^4 / var_m = 4 ln n.
  fs.threshold = std::pow(2.0 * ln_neff * var_m, 0.25);
  return m;
}

// Sign of edge `ej`'s feedthrough under c: the convention's where it is
// known, else the one that fits (none while c is still zero).
double edge_sign(const EdgeJump& ej, const Vec4& c, bool free_signs) {
  if (ej.sign_known && !free_signs) return 1.0;
  const double dot = ej.j.dot(feed_map(ej) * c);
  return dot < 0.0 ? -1.0 : dot > 0.0 ? 1.0 : 0.0;
}

// Least-squares feedthrough c (re/im c_x, re/im c_y) over the edges, with the
// sign the wave phase convention gives (edges near the branch cut of the
// pattern angle with the sign that fits) or (free_signs) one sign per edge,
// iterated from `c`. Its cost and the 1-sigma of the larger |c_k|, scaled by
// the scatter of the edges about the fit when it exceeds the noise
// (extrapolation errors the noise alone does not cover).
Vec4 solve_feedthrough(const std::vector<EdgeJump>& jumps, bool free_signs, Vec4 c, double& cost,
                       double& sigma) {
  for (int it = 0; it < 5; ++it) {
    Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
    Vec4 rhs = Vec4::Zero();
    for (const auto& ej : jumps) {
      const double sgn = edge_sign(ej, c, free_signs);
      if (sgn == 0.0) continue;  // an edge of unknown sign before c is known
      const Eigen::Matrix4d f = feed_map(ej);
      a += f.transpose() * f / ej.var;
      rhs += sgn * f.transpose() * ej.j / ej.var;
    }
    c = a.ldlt().solve(rhs);
    cost = 0.0;
    for (const auto& ej : jumps) {
      const double sgn = edge_sign(ej, c, free_signs);
      cost += (ej.j - sgn * feed_map(ej) * c).squaredNorm() / ej.var;
    }
    const Eigen::Matrix4d cov = a.inverse();
    const double dof = std::max(1.0, 3.0 * static_cast<double>(jumps.size()) - 4.0);
    sigma = std::sqrt(std::max(cov(0, 0) + cov(1, 1), cov(2, 2) + cov(3, 3)) / 2.0 *
                      std::max(1.0, cost / dof));
  }
  return c;
}

// One sign per edge leaves the overall sign of c open: it is the one the
// edges clear of the branch cut agree with under the wave phase convention
// (a producer with another convention then still gets the pump's sign where
// the two agree most).
Vec4 orient_to_convention(const std::vector<EdgeJump>& jumps, const Vec4& c) {
  double agree = 0.0;
  for (const auto& ej : jumps) {
    if (ej.sign_known) agree += ej.j.dot(feed_map(ej) * c) / ej.var;
  }
  return agree < 0.0 ? Vec4(-c) : c;
}

void debug_edges(const Dataset& d, const std::vector<EdgeJump>& jumps,
                 const std::vector<const Edge*>& used) {
  for (std::size_t i = 0; i < jumps.size(); ++i) {
    const auto z = cplx2(jumps[i].j);
    const cplx u = std::conj(jumps[i].phasor) / jumps[i].pump_v;
    std::fprintf(
        stderr, "edge %zu%s t=%.3f |J|/sd=%.2f V=%.2f phi=%.1f wx=%.2e@%.1f wy=%.2e@%.1f\n", i,
        jumps[i].sign_known ? "" : "?", d.t_s[used[i]->forced_rows[0]],
        jumps[i].j.norm() / std::sqrt(jumps[i].var), jumps[i].pump_v,
        std::arg(jumps[i].phasor) * 180 / kPi, std::abs(z[0] * u), std::arg(z[0] * u) * 180 / kPi,
        std::abs(z[1] * u), std::arg(z[1] * u) * 180 / kPi);
    std::string pv = fmt(" skip %.0f:", static_cast<double>(used[i]->pump_off_rows));
    for (double v : used[i]->forced_pump_v)
      pv += fmt(" %.2f", v);
    std::fprintf(stderr, "   pump%s\n", pv.c_str());
  }
}

}  // namespace

FeedStat feedthrough_stat(const Dataset& d, const Params& p, double ln_neff) {
  FeedStat fs;
  // Only the switch-offs: there the forces were steady and the free decay
  // that follows is clean, while a control loop starting up makes the
  // switch-ons transients that no low-order extrapolation follows.
  std::vector<const Edge*> used;
  for (const auto& e : d.edges) {
    if (e.at_start) used.push_back(&e);
  }
  if (d.edges.size() < 3 || used.size() < 3) return fs;
  std::vector<EdgeJump> jumps;
  std::vector<const Edge*> kept;
  for (const auto* e : used) {
    // An edge without a pump (forcers alone) or where the fitted pump is a
    // small part of the rows' own is not evidence: there is no feedthrough
    // to see, or the pump there is what the fit leaves of a moving one.
    const EdgeJump ej = edge_jump(d, p, *e);
    if (!(e->pump_v > 0.0) || ej.pump_v < kMinEdgePumpShare * e->pump_v ||
        e->pump_off_rows > kMaxPumpOffRows)
      continue;
    jumps.push_back(ej);
    kept.push_back(e);
  }
  used.swap(kept);
  fs.dropped = drop_transients(jumps, used);
  if (jumps.size() < 3) return fs;
  // Every edge near the branch cut: the convention is the only reference.
  if (std::none_of(jumps.begin(), jumps.end(), [](const EdgeJump& ej) { return ej.sign_known; })) {
    for (auto& ej : jumps)
      ej.sign_known = true;
  }
  const bool debug = std::getenv("HRG_AUDIT_DEBUG") != nullptr;
  if (debug) debug_edges(d, jumps, used);
  const std::array<cplx, 2> m = sign_free_detection(jumps, ln_neff, fs);
  fs.testable = true;
  fs.edges = static_cast<int>(jumps.size());
  // Estimate: first with the sign the wave phase convention gives, then with
  // one sign per edge (for a source whose drive phase flips by pi with
  // another convention); the free signs are taken only when they fit much
  // better than the freedom they add.
  double fixed_cost = 0.0, fixed_sigma = 0.0;
  Vec4 best_c = solve_feedthrough(jumps, false, Vec4::Zero(), fixed_cost, fixed_sigma);
  fs.sigma = fixed_sigma;
  double best_cost = 1e300, best_sigma = 0.0;
  Vec4 free_c = Vec4::Zero();
  for (double rel : {1.0, -1.0}) {
    double cost = 0.0, sigma = 0.0;
    const Vec4 c = solve_feedthrough(jumps, true, real4({std::sqrt(m[0]), rel * std::sqrt(m[1])}),
                                     cost, sigma);
    if (cost < best_cost) best_cost = cost, free_c = c, best_sigma = sigma;
  }
  if (debug) {
    std::fprintf(
        stderr, "feedthrough: fixed-sign cost %.1f |c| %.3g, free-sign cost %.1f |c| %.3g\n",
        fixed_cost, std::max(std::hypot(best_c(0), best_c(1)), std::hypot(best_c(2), best_c(3))),
        best_cost, std::max(std::hypot(free_c(0), free_c(1)), std::hypot(free_c(2), free_c(3))));
  }
  if (fixed_cost - best_cost > 2.0 * static_cast<double>(jumps.size()) + 25.0) {
    best_c = orient_to_convention(jumps, free_c);
    fs.sigma = best_sigma;
  }
  fs.c_re_im = {best_c(0), best_c(1), best_c(2), best_c(3)};
  fs.c_x = std::hypot(best_c(0), best_c(1));
  fs.c_y = std::hypot(best_c(2), best_c(3));
  return fs;
}

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
