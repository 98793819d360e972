// SPDX-License-Identifier: MIT
// The drive feedthrough seen on the switching edges (feedthrough_stat): each
// switch-off's jump against the free-decay model extrapolated to the edge,
// and the feedthrough that explains them.
#include "selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>

#include <Eigen/Dense>

#include "dsp/wave_variables.hpp"
#include "number_text.hpp"

namespace hrg::audit::detail {

namespace {

constexpr double kPi = std::numbers::pi;

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

// Sign-free detection: the weighted mean of w^2 with w = J e^{-i phi} / V per
// pickoff (the phase of the vibration is defined modulo pi), minus its noise
// expectation. The noise of w is the jump's over the pump, v = var / V^2 per
// part, so each edge's w^2 is weighed by the inverse of its noise variance (4 v^2), as the
// least-squares estimate weighs its jumps by V^2 / var: equal weights let a
// switch-off at a pump near zero (an amplitude loop just off its lower limit,
// which holds no feedthrough to see) take the whole variance of the mean.
// Fills dchi2 and threshold; returns the mean of w^2 per pickoff.
std::array<cplx, 2> sign_free_detection(const std::vector<EdgeJump>& jumps, double ln_neff,
                                        FeedStat& fs) {
  auto noise_of_w = [](const EdgeJump& ej) { return ej.var / (ej.pump_v * ej.pump_v); };
  double weight_sum = 0.0;
  for (const auto& ej : jumps)
    weight_sum += 1.0 / (noise_of_w(ej) * noise_of_w(ej));
  std::array<cplx, 2> m{};
  for (const auto& ej : jumps) {
    const cplx u = std::conj(ej.phasor) / ej.pump_v;
    const auto z = cplx2(ej.j);
    const double v = noise_of_w(ej);
    const double a = 1.0 / (v * v * weight_sum);
    const Eigen::Matrix4d& pr = ej.proj;
    for (int k = 0; k < 2; ++k) {
      const cplx w = z[static_cast<std::size_t>(k)] * u;
      const cplx bias =
          v * cplx(pr(2 * k, 2 * k) - pr(2 * k + 1, 2 * k + 1), 2.0 * pr(2 * k, 2 * k + 1)) *
          std::conj(ej.phasor * ej.phasor);
      m[static_cast<std::size_t>(k)] += a * (w * w - bias);
    }
  }
  // The weighted mean's noise: sum of a^2 4 v^2 over the edges, which these
  // weights make 4 / weight_sum (equal weights: the mean of 4 v^2 over n).
  const double s4_over_n = 4.0 / weight_sum;
  const double var_m = 2.0 * s4_over_n;
  fs.dchi2 = 2.0 * (std::norm(m[0]) + std::norm(m[1])) / var_m;
  fs.threshold = std::pow(4.0 * ln_neff * s4_over_n, 0.25);
  if (std::getenv("HRG_AUDIT_DEBUG"))
    std::fprintf(stderr, "feedthrough sign-free: dchi2 %.1f threshold %.3g over %zu edges\n",
                 fs.dchi2, fs.threshold, jumps.size());
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

}  // namespace hrg::audit::detail
