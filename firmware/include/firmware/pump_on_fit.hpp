// SPDX-License-Identifier: MIT
#pragma once

// The pump-on side of a switch-off edge (fw::PumpEdgeCheck): the corrected
// quadratures of the last pump-on rows, fitted to be taken to the switch
// instant. While the pump runs the vibration is not a line when the pump moves:
// the parametric pump changes the vibration at a rate proportional to V^2 (its
// energy and its frequency pull), so a pump that rises from 0 to its limit
// within the rows bends the vibration there. Each quadrature is fitted with
// 1, t and q(t) = the integral of V^2 over the rows (each quadrature its own
// coefficient: any complex multiple of the envelope). Where the pump holds one
// level q is a line in t and the fit is the line.
//
// The residual feedthrough r P rides on the rows too, and moves with the
// pump: the AGC's chatter (0 to 4 V from row to row) puts r times it into
// the rows' misfit, 8e-4 V at r = 8e-4 V/V against a row noise of 3e-5 V.
// rss_without_feedthrough takes that part out for the noise estimate.
//
// No heap; sums only (one pass over the rows, one 3x3 solve at the end).

#include <array>
#include <cstdint>

namespace hrg::fw {

class PumpOnFit {
 public:
  struct Result {
    std::array<double, 4> v{};  // quadratures at t_e (V)
    double var_factor = 0.0;    // variance of a value at t_e over that of one row
    double rss = 0.0;           // residual sum of squares, 4 quadratures pooled (V^2)
    uint32_t parameters = 2;    // per quadrature: 2 (a line) or 3 (with the pump's q)
    // The pump, weighted as the fit weights its rows at t_e (V, complex in the frame).
    double pump_re_v = 0.0;
    double pump_im_v = 0.0;
    // Residual cross sums of the rows with the pump's motion about the fit,
    // per channel (x, y), and the pump's own (rss_without_feedthrough).
    std::array<double, 2> b{};
    std::array<double, 2> c{};
    double pump_rss = 0.0;
  };

  // One row: t its index (rows, increasing), q its quadratures {cx, sx, cy,
  // sy} and (p_re, p_im) the pump it saw, both in the edge's frame.
  void add(double t, const std::array<double, 4>& q, double p_re, double p_im);
  // The fit taken to t_e (rows; after the last row the pump holds its last
  // level); `bend` false: a line whatever the pump did.
  Result at(double t_e, bool bend = true) const;
  // The rows' residual sum of squares once a feedthrough r = {x re, x im,
  // y re, y im} (V/V) has followed the pump about the fit (>= 0).
  static double rss_without_feedthrough(const Result& fit, const std::array<double, 4>& r);

 private:
  static constexpr std::size_t kSeries = 6;  // cx, sx, cy, sy, P re, P im
  double n_ = 0.0;
  std::array<double, kSeries> ref_{};  // the first row's values (subtracted)
  double q_ = 0.0;                     // the integral of V^2 up to the last row's centre
  double last_p2_ = 0.0;               // V^2 of the last row
  double last_t_ = 0.0;
  // Sums of the regressors a = (1, t, q) and of the series against them.
  std::array<double, 6> aa_{};  // n, t, q, tt, tq, qq
  std::array<std::array<double, 3>, kSeries> ay_{};
  std::array<double, kSeries> yy_{};
  std::array<std::array<double, 2>, 4> yp_{};  // quadrature x pump part
};

}  // namespace hrg::fw
