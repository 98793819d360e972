// SPDX-License-Identifier: MIT
#include "dataset.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "dsp/wave_variables.hpp"

namespace hrg::audit::detail {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::size_t kMinFreeSamples = 20;
constexpr std::size_t kMinForcedSamples = 8;
constexpr std::size_t kEdgeRows = 10;
constexpr std::size_t kSlopeRows = 40;

struct Run {
  std::size_t first = 0, last = 0;  // inclusive rows
  bool exc = false;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

const std::vector<double>* optional_column(const recording::Recording& rec, const char* name) {
  return rec.has_column(name) ? &rec.column(name) : nullptr;
}

}  // namespace

Dataset build_dataset(const recording::Recording& rec, int max_blocks) {
  Dataset d;
  const std::size_t n = rec.rows();
  d.f_ref_hz = rec.f_ref_hz();
  d.angular_gain = rec.angular_gain();
  const auto& t = rec.column("t_s");
  const auto& cx = rec.column("cx_v");
  const auto& sx = rec.column("sx_v");
  const auto& cy = rec.column("cy_v");
  const auto& sy = rec.column("sy_v");
  const auto& exc = rec.column("exc");
  const auto* pump = optional_column(rec, "pump_v");
  const auto* temp = optional_column(rec, "temp_c");
  const auto* rate = optional_column(rec, "rate_dps");
  const auto* fref = optional_column(rec, "f_ref_hz");
  d.has_pump = pump != nullptr;
  d.has_temp = temp != nullptr;
  d.has_rate = rate != nullptr;
  d.t_s = t;

  // Runs of equal exc, cut at gaps (a gap is never bridged by the model).
  std::vector<bool> gap_before(n, false);
  for (const auto& g : rec.gaps())
    gap_before[g.row] = true;
  std::vector<Run> runs;
  for (std::size_t i = 0; i < n; ++i) {
    const bool e = exc[i] != 0.0;
    if (runs.empty() || runs.back().exc != e || gap_before[i]) {
      runs.push_back({i, i, e});
    } else {
      runs.back().last = i;
    }
  }
  for (const auto& g : rec.gaps()) {
    d.notes.push_back("gap of " + std::to_string(g.t_after_s - g.t_before_s) +
                      " s after t = " + std::to_string(g.t_before_s) + " s (file line " +
                      std::to_string(g.line) + "): segments cut there, nothing interpolated");
  }

  // Wave variables of the raw rows; continuous pattern angle and phase.
  std::vector<double> theta(n), phase(n), a2(n);
  dsp::ThetaUnwrapper<double> unwrap;
  for (std::size_t i = 0; i < n; ++i) {
    const auto w = dsp::wave_variables<double>({cx[i], sx[i], cy[i], sy[i]});
    theta[i] = unwrap.update(w.theta_A_rad);
    a2[i] = w.a_A * w.a_A;
    phase[i] = w.phase_rad;
    if (i > 0 && !gap_before[i]) {
      // The wave phase is defined modulo pi: keep it continuous.
      phase[i] = phase[i - 1] + std::remainder(phase[i] - phase[i - 1], kPi);
    }
  }
  // Phase in the frame of the fixed metadata reference.
  std::vector<double> ref_phase(n, 0.0);
  if (fref != nullptr) {
    for (std::size_t i = 1; i < n; ++i) {
      const double f_mid = 0.5 * ((*fref)[i] + (*fref)[i - 1]) - d.f_ref_hz;
      ref_phase[i] = ref_phase[i - 1] + 2.0 * kPi * f_mid * (t[i] - t[i - 1]);
    }
  }
  // Carrier: median wave frequency over the free-decay runs.
  std::vector<double> slopes;
  for (const auto& r : runs) {
    if (r.exc || r.last - r.first + 1 < kMinFreeSamples) continue;
    const double dphi = (phase[r.last] + ref_phase[r.last]) - (phase[r.first] + ref_phase[r.first]);
    slopes.push_back(dphi / (t[r.last] - t[r.first]));
  }
  if (slopes.empty()) {
    throw std::runtime_error("recording has no free-decay segment (exc = 0) of at least " +
                             std::to_string(kMinFreeSamples) + " samples: nothing to fit");
  }
  d.carrier_rad_s = median(slopes);
  d.frame_phase_rad.resize(n);
  d.x.resize(n);
  d.y.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    d.frame_phase_rad[i] = ref_phase[i] - d.carrier_rad_s * (t[i] - t[0]);
    const cplx rot = std::polar(1.0, d.frame_phase_rad[i]);
    d.x[i] = cplx(cx[i], -sx[i]) * rot;
    d.y[i] = cplx(cy[i], -sy[i]) * rot;
    phase[i] += d.frame_phase_rad[i];
  }

  // White noise from second differences of the slow, derotated envelopes.
  std::vector<double> d2;
  for (const auto& r : runs) {
    if (r.exc) continue;
    for (std::size_t i = r.first + 1; i + 1 <= r.last; ++i) {
      const cplx ax = d.x[i + 1] - 2.0 * d.x[i] + d.x[i - 1];
      const cplx ay = d.y[i + 1] - 2.0 * d.y[i] + d.y[i - 1];
      d2.push_back(std::abs(ax.real()));
      d2.push_back(std::abs(ax.imag()));
      d2.push_back(std::abs(ay.real()));
      d2.push_back(std::abs(ay.imag()));
    }
  }
  d.noise_v = median(d2) * 1.482602 / std::sqrt(6.0);
  if (!(d.noise_v > 0.0)) d.noise_v = 1e-12;

  // Temperature reference and spans.
  double tmin = 1e300, tmax = -1e300, amin = 1e300, amax = -1e300, rmin = 1e300, rmax = -1e300;
  for (std::size_t i = 0; i < n; ++i) {
    if (temp) tmin = std::min(tmin, (*temp)[i]), tmax = std::max(tmax, (*temp)[i]);
    if (exc[i] == 0.0) amin = std::min(amin, a2[i]), amax = std::max(amax, a2[i]);
    const double rr = rate ? (*rate)[i] * kPi / 180.0 : 0.0;
    rmin = std::min(rmin, rr);
    rmax = std::max(rmax, rr);
  }
  d.temp_ref_c = temp ? 0.5 * (tmin + tmax) : 0.0;
  d.temp_span_c = temp ? tmax - tmin : 0.0;
  d.a2_span_v2 = amax > amin ? amax - amin : 0.0;
  d.rate_span_rad_s = rmax - rmin;

  // Block length: enough blocks for the envelope, short enough for the
  // fourth-order propagator (|A'| T_block <= 0.2).
  std::size_t n_free = 0;
  for (const auto& r : runs) {
    if (!r.exc && r.last - r.first + 1 >= kMinFreeSamples) n_free += r.last - r.first + 1;
  }
  const double dt = rec.typical_step_s();
  const double max_rate = std::max(std::abs(rmin), std::abs(rmax));
  const double a_fast = max_rate * d.angular_gain + 0.05;
  const auto nb_acc = static_cast<std::size_t>(std::max(1.0, std::floor(0.2 / (a_fast * dt))));
  const std::size_t nb_cost =
      (n_free + static_cast<std::size_t>(max_blocks) - 1) / static_cast<std::size_t>(max_blocks);
  const std::size_t nb = std::clamp<std::size_t>(nb_cost, 1, nb_acc);
  d.samples_per_block = static_cast<int>(nb);

  std::size_t seg_index = 0;
  for (std::size_t ri = 0; ri < runs.size(); ++ri) {
    const Run& r = runs[ri];
    const std::size_t len = r.last - r.first + 1;
    if (r.exc) {
      if (len < kMinForcedSamples) continue;
      // Only the quiet part of an excitation segment tells the frequency: the
      // quadrature nulled and the pattern not being moved by the forcers. With
      // a quadrature a_B the forces that steer the pattern pull the wave phase
      // by -2 (a_B/a_A) theta'_cmd, which no resonator parameter explains.
      const std::size_t h = 10;
      std::size_t best_first = 0, best_len = 0, run_first = 0, run_len = 0;
      for (std::size_t i = r.first; i <= r.last; ++i) {
        bool ok = i >= r.first + h && i + h <= r.last;
        if (ok) {
          const double a = std::sqrt(a2[i]);
          const auto w = dsp::wave_variables<double>({cx[i], sx[i], cy[i], sy[i]});
          const double th_rate = (theta[i + h] - theta[i - h]) / (t[i + h] - t[i - h]);
          const double free_rate = rate ? -0.5 * d.angular_gain * (*rate)[i] * kPi / 180.0 : 0.0;
          ok = std::abs(w.a_B) < 1e-3 * a + 3.0 * d.noise_v && std::abs(th_rate - free_rate) < 2e-3;
        }
        if (ok) {
          if (run_len == 0) run_first = i;
          ++run_len;
          if (run_len > best_len) best_len = run_len, best_first = run_first;
        } else {
          run_len = 0;
        }
      }
      const double dt_typ = rec.typical_step_s();
      if (best_len < 20 || static_cast<double>(best_len) * dt_typ < 0.5) continue;
      const std::size_t q0 = best_first, q1 = best_first + best_len - 1;
      ForcedSegment f;
      f.first_row = q0;
      f.last_row = q1;
      const std::size_t k = 3;
      double ts = 0, te = 0, ps = 0, pe = 0;
      for (std::size_t j = 0; j < k; ++j) {
        ts += t[q0 + j] / k, ps += phase[q0 + j] / k;
        te += t[q1 - j] / k, pe += phase[q1 - j] / k;
      }
      f.t0_s = ts;
      f.t1_s = te;
      f.freq_rad_s = (pe - ps) / (te - ts);
      double c4 = 0, s4 = 0, v2 = 0, aa = 0, tc = 0, rr = 0;
      for (std::size_t i = q0; i <= q1; ++i) {
        c4 += std::cos(4.0 * theta[i]);
        s4 += std::sin(4.0 * theta[i]);
        v2 += pump ? (*pump)[i] * (*pump)[i] : 0.0;
        aa += a2[i];
        tc += temp ? (*temp)[i] : 0.0;
        rr += rate ? (*rate)[i] * kPi / 180.0 : 0.0;
      }
      const auto m = static_cast<double>(best_len);
      f.mean_c4 = c4 / m, f.mean_s4 = s4 / m, f.mean_v2 = v2 / m, f.mean_a2 = aa / m;
      f.mean_temp_c = tc / m, f.mean_rate_rad_s = rr / m;
      f.theta0_rad = theta[q0];
      f.theta1_rad = theta[q1];
      f.se_rad_s =
          std::sqrt(2.0 / k) * d.noise_v / std::sqrt(std::max(f.mean_a2, 1e-30)) / (te - ts);
      d.forced.push_back(f);
      continue;
    }
    if (len < kMinFreeSamples) continue;
    FreeSegment s;
    s.first_row = r.first;
    s.last_row = r.last;
    s.t0_s = t[r.first];
    s.t1_s = t[r.last];
    s.first_block = d.blocks.size();
    for (std::size_t b0 = r.first; b0 <= r.last; b0 += nb) {
      const std::size_t b1 = std::min(r.last, b0 + nb - 1);
      Block b;
      b.n = static_cast<double>(b1 - b0 + 1);
      for (std::size_t i = b0; i <= b1; ++i)
        b.t_s += t[i] / b.n;
      for (std::size_t i = b0; i <= b1; ++i) {
        const double tau = t[i] - b.t_s;
        b.m2 += tau * tau / b.n, b.m3 += tau * tau * tau / b.n, b.m4 += tau * tau * tau * tau / b.n;
        b.x += d.x[i] / b.n;
        b.y += d.y[i] / b.n;
        b.temp_c += temp ? (*temp)[i] / b.n : 0.0;
        b.rate_rad_s += rate ? (*rate)[i] * kPi / 180.0 / b.n : 0.0;
        b.a2_v2 += a2[i] / b.n;
        b.theta_rad += theta[i] / b.n;
      }
      d.blocks.push_back(b);
    }
    s.n_blocks = d.blocks.size() - s.first_block;
    d.free.push_back(s);
    // Edges with the neighbouring excitation runs (no gap between them).
    auto add_edge = [&](const Run& fr, bool at_start) {
      Edge e;
      e.free_segment = seg_index;
      e.at_start = at_start;
      const std::size_t m = std::min<std::size_t>(kEdgeRows, fr.last - fr.first + 1);
      double v = 0.0;
      for (std::size_t j = 0; j < m; ++j) {
        const std::size_t row = at_start ? fr.last - j : fr.first + j;
        e.forced_rows.push_back(row);
        v += pump ? std::abs((*pump)[row]) / static_cast<double>(m) : 1.0 / static_cast<double>(m);
      }
      e.pump_v = v;
      const std::size_t run_rows = fr.last - fr.first + 1;
      for (std::size_t j = m; j < std::min(run_rows, m + kSlopeRows); ++j)
        e.slope_rows.push_back(at_start ? fr.last - j : fr.first + j);
      if (m >= 4) d.edges.push_back(e);
    };
    if (ri > 0 && runs[ri - 1].exc && runs[ri - 1].last + 1 == r.first && !gap_before[r.first]) {
      add_edge(runs[ri - 1], true);
    }
    if (ri + 1 < runs.size() && runs[ri + 1].exc && !gap_before[runs[ri + 1].first]) {
      add_edge(runs[ri + 1], false);
    }
    ++seg_index;
  }
  // Hold out every fourth free segment (whole segments), when there are enough.
  if (d.free.size() >= 4) {
    for (std::size_t i = 2; i < d.free.size(); i += 4)
      d.free[i].heldout = true;
  }
  return d;
}

}  // namespace hrg::audit::detail
