// SPDX-License-Identifier: MIT
// The excitation segments of a recording: their quiet stretch, the pump's
// jitter, and their observations (mean frequency, amplitude balance,
// pattern-angle drift) with the offset and drift shapes of the four
// demodulated signals in them (ForcedSegment::per_offset).
#include "dataset_rows.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <utility>

#include "dsp/wave_variables.hpp"

namespace hrg::audit::detail {

namespace {

constexpr double kPi = std::numbers::pi;

// Longest quiet stretch of an excitation run: the quadrature nulled and the
// pattern not being moved by the forcers. With a quadrature a_B the forces
// that steer the pattern pull the wave phase by -2 (a_B/a_A) theta'_cmd,
// which no resonator parameter explains. Returns {first row, length}.
std::pair<std::size_t, std::size_t> quiet_stretch(const Rows& r, const Run& run, const Dataset& d) {
  const std::size_t h = 10;
  std::size_t best_first = 0, best_len = 0, run_first = 0, run_len = 0;
  for (std::size_t i = run.first; i <= run.last; ++i) {
    bool ok = i >= run.first + h && i + h <= run.last;
    if (ok) {
      const double a = std::sqrt(r.a2[i]);
      const auto w = dsp::wave_variables<double>({r.cx[i], r.sx[i], r.cy[i], r.sy[i]});
      const double th_rate = (r.theta[i + h] - r.theta[i - h]) / (r.t[i + h] - r.t[i - h]);
      const double free_rate = -0.5 * d.angular_gain * r.rate_rad_s(i);
      ok = std::abs(w.a_B_v) < 1e-3 * a + 3.0 * d.noise_v && std::abs(th_rate - free_rate) < 2e-3;
    }
    if (ok) {
      if (run_len == 0) run_first = i;
      ++run_len;
      if (run_len > best_len) best_len = run_len, best_first = run_first;
    } else {
      run_len = 0;
    }
  }
  return {best_first, best_len};
}

// (pump_v / a_A) e^{2 i theta} of row i, theta wrapped to (-pi/4, pi/4]: the
// branch the wave phase, and a pump that follows it, take. A feedthrough
// V e^{i phi} c adds V (c_x cos 2 theta + c_y sin 2 theta) / a_A to the
// measured wave along its own phase (0 without a pump column).
cplx pump_per_amplitude(const Rows& r, std::size_t i) {
  if (!r.pump) return 0.0;
  const double th = std::remainder(r.theta[i], kPi / 2.0);
  return std::polar(std::abs((*r.pump)[i]) / std::sqrt(std::max(r.a2[i], 1e-30)), 2.0 * th);
}

// Row-to-row jitter of |pump_v| over rows [q0, q1] relative to its mean: the
// rms of its second differences over sqrt(6) (white jitter's standard
// deviation; a pump the loop moves smoothly leaves ~0). 0 without a pump.
double pump_jitter(const Rows& r, std::size_t q0, std::size_t q1) {
  if (!r.pump || q1 < q0 + 2) return 0.0;
  double level = 0.0, d2 = 0.0;
  for (std::size_t i = q0; i <= q1; ++i)
    level += std::abs((*r.pump)[i]);
  for (std::size_t i = q0 + 1; i < q1; ++i) {
    const double a =
        std::abs((*r.pump)[i + 1]) - 2.0 * std::abs((*r.pump)[i]) + std::abs((*r.pump)[i - 1]);
    d2 += a * a;
  }
  level /= static_cast<double>(q1 - q0 + 1);
  if (!(level > 0.0)) return 0.0;
  return std::sqrt(d2 / static_cast<double>(q1 - q0 - 1) / 6.0) / level;
}

// Phase (carrier frame), ln a_A and pattern angle of row i with `dv` added to
// demodulated signal k (cx, sx, cy, sy), each brought next to the row's own.
std::array<double, 3> row_envelope(const Rows& r, const Dataset& d, std::size_t i, std::size_t k,
                                   double dv) {
  std::array<double, 4> v{r.cx[i], r.sx[i], r.cy[i], r.sy[i]};
  v[k] += dv;
  const auto w = dsp::wave_variables<double>({v[0], v[1], v[2], v[3]});
  const double phase = w.phase_rad + d.frame_phase_rad[i];
  return {r.phase[i] + std::remainder(phase - r.phase[i], kPi), std::log(std::max(w.a_A_v, 1e-15)),
          r.theta[i] + std::remainder(w.theta_A_rad - r.theta[i], kPi / 2.0)};
}

// ForcedSegment::per_offset by central differences at the segment's end rows
// (k of them at each end for the phase and ln a_A, single rows for the angle).
void offset_sensitivity(const Rows& r, const Dataset& d, std::size_t k, ForcedSegment& f) {
  const std::size_t q0 = f.first_row, q1 = f.last_row;
  const double dv = 1e-4 * std::sqrt(std::max(r.a2[q1], 1e-30));
  const double t_mid = 0.5 * (r.t.front() + r.t.back());
  for (std::size_t c = 0; c < 8; ++c) {
    // Change of (phase, ln a_A, theta) at row i under the offset c.
    auto delta = [&](std::size_t i) {
      const double s = c < 4 ? 1.0 : r.t[i] - t_mid;
      const auto up = row_envelope(r, d, i, c % 4, s * dv),
                 dn = row_envelope(r, d, i, c % 4, -s * dv);
      return std::array<double, 3>{(up[0] - dn[0]) / (2.0 * dv), (up[1] - dn[1]) / (2.0 * dv),
                                   (up[2] - dn[2]) / (2.0 * dv)};
    };
    double dphase = 0.0, dlna = 0.0;
    for (std::size_t j = 0; j < k; ++j) {
      const auto e = delta(q1 - j), b = delta(q0 + j);
      dphase += (e[0] - b[0]) / static_cast<double>(k);
      dlna += (e[1] - b[1]) / static_cast<double>(k);
    }
    f.per_offset[0][c] = dphase / (f.t1_s - f.t0_s);
    f.per_offset[1][c] = dlna / (f.t1_s - f.t0_s);
    f.per_offset[2][c] = (delta(q1)[2] - delta(q0)[2]) / f.angle_span_s;
  }
}

}  // namespace

// Mean wave frequency and mean inputs over the quiet part of an excitation run.
void add_forced_segment(const Rows& r, const Run& run, double dt_typ, Dataset& d) {
  const auto [q0, best_len] = quiet_stretch(r, run, d);
  if (best_len < 20 || static_cast<double>(best_len) * dt_typ < 0.5) return;
  const std::size_t q1 = q0 + best_len - 1;
  if (std::getenv("HRG_AUDIT_DEBUG"))
    std::fprintf(stderr, "excitation %.2f-%.2f s: pump jitter %.3g of its level\n", r.t[q0],
                 r.t[q1], pump_jitter(r, q0, q1));
  if (pump_jitter(r, q0, q1) > kMaxPumpJitter) {
    ++d.forced_jittery;  // its pump_v, mean V^2 and ends alias the pump
    return;
  }
  ForcedSegment f;
  f.first_row = q0;
  f.last_row = q1;
  const std::size_t k = kEndRows;
  double ts = 0, te = 0, ps = 0, pe = 0, ls = 0, le = 0;
  cplx gs, ge;  // mean (pump_v / a_A) e^{2 i theta} at the start and the end
  for (std::size_t j = 0; j < k; ++j) {
    ts += r.t[q0 + j] / k, ps += r.phase[q0 + j] / k;
    f.theta_start_rad[j] = r.theta[q0 + j];
    f.theta_end_rad[j] = r.theta[q1 - j];
    te += r.t[q1 - j] / k, pe += r.phase[q1 - j] / k;
    ls += 0.5 * std::log(std::max(r.a2[q0 + j], 1e-30)) / k;
    le += 0.5 * std::log(std::max(r.a2[q1 - j], 1e-30)) / k;
    gs += pump_per_amplitude(r, q0 + j) / static_cast<double>(k);
    ge += pump_per_amplitude(r, q1 - j) / static_cast<double>(k);
  }
  f.t0_s = ts;
  f.t1_s = te;
  f.freq_rad_s = (pe - ps) / (te - ts);
  f.ft_gx_per_s = (ge - gs).real() / (te - ts);
  f.ft_gy_per_s = (ge - gs).imag() / (te - ts);
  double c4 = 0, s4 = 0, v2 = 0, v2c4 = 0, v2s4 = 0, aa = 0, tc = 0, rr = 0;
  cplx h;
  for (std::size_t i = q0; i <= q1; ++i) {
    const double ci = std::cos(4.0 * r.theta[i]), si = std::sin(4.0 * r.theta[i]);
    const double vi = r.pump ? (*r.pump)[i] * (*r.pump)[i] : 0.0;
    c4 += ci, s4 += si, v2 += vi, v2c4 += vi * ci, v2s4 += vi * si;
    h += pump_per_amplitude(r, i) * vi;
    aa += r.a2[i];
    tc += r.temp ? (*r.temp)[i] : 0.0;
    rr += r.rate_rad_s(i);
  }
  const auto m = static_cast<double>(best_len);
  f.mean_c4 = c4 / m, f.mean_s4 = s4 / m, f.mean_v2 = v2 / m, f.mean_a2 = aa / m;
  f.mean_v2c4 = v2c4 / m, f.mean_v2s4 = v2s4 / m;
  f.ft_hx_v2 = h.real() / m, f.ft_hy_v2 = h.imag() / m;
  f.dlna_per_s = (le - ls) / (te - ts);
  f.mean_temp_c = tc / m, f.mean_rate_rad_s = rr / m;
  f.theta0_rad = r.theta[q0];
  f.theta1_rad = r.theta[q1];
  f.angle_span_s = r.t[q1] - r.t[q0];
  double rate_integral = 0.0;
  for (std::size_t i = q0; i < q1; ++i)
    rate_integral += 0.5 * (r.rate_rad_s(i) + r.rate_rad_s(i + 1)) * (r.t[i + 1] - r.t[i]);
  f.angle_rate_rad_s = rate_integral / f.angle_span_s;
  const cplx dg = pump_per_amplitude(r, q1) - pump_per_amplitude(r, q0);
  f.ft_ax_per_s = dg.real() / f.angle_span_s;
  f.ft_ay_per_s = dg.imag() / f.angle_span_s;
  // A row's phase noise is noise / a_A at that row's own amplitude, and the
  // frequency is read from the end rows alone: on the firmware's ring-up
  // (a_A 0.1 V at its start, 0.95 V at its end) the start carries nearly all
  // of it, and the segment's mean a_A^2 put its sigma 3.6x low (1.08e-6
  // against 3.94e-6 rad/s, default scenario at seed 5).
  double inv_a2_ends = 0.0;  // sum over the 2k end rows of 1 / a_A^2
  for (std::size_t j = 0; j < k; ++j)
    inv_a2_ends += 1.0 / std::max(r.a2[q0 + j], 1e-30) + 1.0 / std::max(r.a2[q1 - j], 1e-30);
  const double noise2 = d.noise_v * d.noise_v;
  f.se_rad_s = std::sqrt(noise2 * inv_a2_ends) / static_cast<double>(k) / (te - ts);
  f.balance_se_per_s = f.se_rad_s;  // ln a_A and the phase see the same noise per row
  // theta from single rows: half the phase's noise per row (theta = arg / 2).
  const double inv_a2_end_rows = 1.0 / std::max(r.a2[q0], 1e-30) + 1.0 / std::max(r.a2[q1], 1e-30);
  f.angle_se_rad_s = std::sqrt(noise2 * inv_a2_end_rows) / 2.0 / f.angle_span_s;
  offset_sensitivity(r, d, k, f);
  d.forced.push_back(f);
}

}  // namespace hrg::audit::detail
