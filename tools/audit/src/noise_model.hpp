// SPDX-License-Identifier: MIT
#pragma once

// The residual noise model of the significance and acceptance tests: an
// autoregressive (AR) model per residual channel (re/im of x and y, one value
// per block), its order chosen by BIC, fitted to the residuals of the model a
// test accepts. Coloured noise (1/f-like on the demodulated signals) is then
// whitened before chi^2 is counted, so slow noise is not taken for structure.
// Noise slower than an AR model of a few lags follows (the slowest octaves of
// 1/f noise, correlated over hundreds of blocks) is held by the variance of
// the whitened residuals at dyadic scales (orthonormal Haar coefficients per
// segment, which decorrelate 1/f-like noise): each scale's chi^2 is counted
// against its own variance where that stands significantly above 1.

#include <array>
#include <vector>

#include "dataset.hpp"

namespace hrg::audit::detail {

struct ArNoise {
  static constexpr int kMaxOrder = 6;
  // Per channel and per order q = 0..p (p the chosen order): a_1..a_q of
  // r_t = sum a_k r_{t-k} + e_t and var(e) in noise units^2. The first rows
  // of a segment are predicted with the orders their lags allow.
  struct Order {
    std::vector<double> coef;
    double var = 1.0;
  };
  std::array<std::vector<Order>, 4> orders;
  // Variance of the whitened residuals' Haar coefficients per pickoff (x:
  // channels 0-1, y: 2-3) and scale (1 = pairs of blocks, j = 2^j blocks),
  // over the white level 1; 1 where not significantly above it.
  static constexpr int kScales = 16;
  std::array<std::array<double, kScales + 1>, 2> scale_var{};
  // Lag-1 coefficient of the excitation segments' observations from one
  // segment to the next (frequency, amplitude balance and pattern-angle
  // drift, each in time order, pooled): 0 unless BIC takes it and it is
  // positive. They are read from the end rows of segments a free window
  // apart, and slow noise on the demodulated signals (an offset beating
  // with the vibration's phase turning in the demodulation frame) moves
  // neighbours alike.
  double forced_rho = 0.0;
  ArNoise() {
    for (auto& v : scale_var)
      v.fill(1.0);
  }
  int order(std::size_t channel) const {
    return orders[channel].empty() ? 0 : static_cast<int>(orders[channel].size()) - 1;
  }
};

// AR model of the free-decay block residuals `res` (4 per block, segments in
// the order of d.free), fitted per channel by pooled least squares over the
// segments; order 0..kMaxOrder by BIC on a common sample.
ArNoise fit_ar_noise(const Dataset& d, const std::vector<double>& res);

// chi^2 of the free-decay residuals after whitening with `ar` (each channel's
// prediction error over its innovation variance; the first rows of a segment
// use the lags they have), plus the excitation-segment residuals filtered by
// forced_rho at unit gain for the fastest shape (slow noise only adds to
// their weights' level, at slow shapes).
double whitened_chi2(const Dataset& d, const std::vector<double>& res, const ArNoise& ar);

// chi^2 of the excitation segments' observations in `res` (the model's
// residual vector, free decays first) that slow noise on the demodulated
// signals explains: an offset on each of cx, sx, cy, sy and one drifting
// linearly in time (the slowest octaves of 1/f noise over a recording), seen
// through each segment's end rows (ForcedSegment::per_offset, over each
// observation's weight), fitted by least squares. Such an offset beats with
// the vibration's phase turning in the demodulation frame and with the pattern
// angle, and the segments' cadence aliases it to slow patterns of the angle.
double slow_offset_chi2(const Dataset& d, const std::vector<double>& res);

}  // namespace hrg::audit::detail
