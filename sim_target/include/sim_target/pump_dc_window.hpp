// SPDX-License-Identifier: MIT
#pragma once

// The DC part of the held pump's V^2, sample by sample, for any reference
// period P (samples), whole or not.
//
// V = V0 cos(psi) at frequency f gives V^2 = V0^2/2 + V0^2/2 cos(2 psi): a
// DC part and one line at 2f, theta = 4 pi / P radians per sample. The mean
// m of the last N = round(P) squares passes that line as
// beta = (1/N) sum_{j<N} e^{-i theta j}: zero when P is whole (5 kHz at
// 100 kHz, N = 20), about 2 % of the line when it is not (P = 16.67 at
// 6 kHz, 19.61 at 5.1 kHz), and that leak, times the displacement, is a
// pump at the wrong phase: a frequency pull and a pump gain that the
// resonator does not have. Two squares of the line, s_n and s_{n-k}, fix
// its complex amplitude, so the DC part is exactly
//
//   a = (m - A s_n + B s_{n-k}) / (1 - A + B),
//   A = Re beta + Im beta cos(k theta) / sin(k theta),  B = Im beta / sin(k theta),
//
// with the lag k in 1..4 that keeps |sin k theta| largest (A, B ~ |beta|,
// so the two squares enter with weights of about 2 %: no gain on the DAC's
// quantisation or on a switching step). The three weights are formed once,
// so a step costs three products and no division. For a whole P the line
// does not leak and a is the mean itself, sum / N, to the bit.

namespace hrg::sim {

struct PumpDcWindow {
  int length = 20;     // N, squares in the sum
  int lag = 1;         // k
  bool whole = true;   // P is a whole number of samples: the mean alone
  double w_sum = 0.0;  // 1 / (N (1 - A + B))
  double w_now = 0.0;  // -A / (1 - A + B)
  double w_lag = 0.0;  // B / (1 - A + B)

  // The DC part from the sum of the last N squares, the newest square and
  // the one `lag` samples older, V^2.
  double dc(double sum, double sq_now, double sq_lag) const {
    if (whole) return sum / length;
    return w_sum * sum + w_now * sq_now + w_lag * sq_lag;
  }
};

// The window for a reference period of `period_samples` (> 1) with at most
// `max_length` squares (the history the caller keeps).
PumpDcWindow pump_dc_window(double period_samples, int max_length);

}  // namespace hrg::sim
