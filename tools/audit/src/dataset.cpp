// SPDX-License-Identifier: MIT
#include "dataset.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "dataset_rows.hpp"
#include "dsp/wave_variables.hpp"

namespace hrg::audit::detail {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::size_t kMinFreeSamples = 20;
constexpr std::size_t kMinForcedSamples = 8;
constexpr std::size_t kEdgeRows = 10;
constexpr std::size_t kSlopeRows = 40;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Runs of equal exc, cut at gaps (a gap is never bridged by the model).
std::vector<Run> cut_runs(const Rows& r) {
  std::vector<Run> runs;
  for (std::size_t i = 0; i < r.n; ++i) {
    const bool e = r.exc[i] != 0.0;
    if (runs.empty() || runs.back().exc != e || r.gap_before[i]) {
      runs.push_back({i, i, e});
    } else {
      runs.back().last = i;
    }
  }
  return runs;
}

void note_gaps(const recording::Recording& rec, Dataset& d) {
  for (const auto& g : rec.gaps()) {
    d.notes.push_back("gap of " + std::to_string(g.t_after_s - g.t_before_s) +
                      " s after t = " + std::to_string(g.t_before_s) + " s (file line " +
                      std::to_string(g.line) + "): segments cut there, nothing interpolated");
  }
}

// Wave variables of the raw rows; continuous pattern angle and phase.
void wave_rows(Rows& r) {
  r.theta.resize(r.n), r.phase.resize(r.n), r.a2.resize(r.n);
  dsp::ThetaUnwrapper<double> unwrap;
  for (std::size_t i = 0; i < r.n; ++i) {
    const auto w = dsp::wave_variables<double>({r.cx[i], r.sx[i], r.cy[i], r.sy[i]});
    r.theta[i] = unwrap.update(w.theta_A_rad);
    r.a2[i] = w.a_A_v * w.a_A_v;
    r.phase[i] = w.phase_rad;
    if (i > 0 && !r.gap_before[i]) {
      // The wave phase is defined modulo pi: keep it continuous.
      r.phase[i] = r.phase[i - 1] + std::remainder(r.phase[i] - r.phase[i - 1], kPi);
    }
  }
}

// Phase of each row's demodulation reference (column f_ref_hz, a reference
// that follows the resonance) against the fixed metadata reference.
std::vector<double> reference_phase(const Rows& r, double f_ref_hz) {
  std::vector<double> ref_phase(r.n, 0.0);
  if (r.fref == nullptr) return ref_phase;
  for (std::size_t i = 1; i < r.n; ++i) {
    const double f_mid = 0.5 * ((*r.fref)[i] + (*r.fref)[i - 1]) - f_ref_hz;
    ref_phase[i] = ref_phase[i - 1] + 2.0 * kPi * f_mid * (r.t[i] - r.t[i - 1]);
  }
  return ref_phase;
}

// Carrier: median wave frequency over the free-decay runs; the envelopes and
// the wave phase are turned into the frame rotating at it.
void derotate(Rows& r, const std::vector<Run>& runs, Dataset& d) {
  const std::vector<double> ref_phase = reference_phase(r, d.f_ref_hz);
  std::vector<double> slopes;
  for (const auto& run : runs) {
    if (run.exc || run.last - run.first + 1 < kMinFreeSamples) continue;
    const double dphi =
        (r.phase[run.last] + ref_phase[run.last]) - (r.phase[run.first] + ref_phase[run.first]);
    slopes.push_back(dphi / (r.t[run.last] - r.t[run.first]));
  }
  if (slopes.empty()) {
    throw std::runtime_error("recording has no free-decay segment (exc = 0) of at least " +
                             std::to_string(kMinFreeSamples) + " samples: nothing to fit");
  }
  d.carrier_rad_s = median(slopes);
  d.frame_phase_rad.resize(r.n);
  d.x.resize(r.n);
  d.y.resize(r.n);
  for (std::size_t i = 0; i < r.n; ++i) {
    d.frame_phase_rad[i] = ref_phase[i] - d.carrier_rad_s * (r.t[i] - r.t[0]);
    const cplx rot = std::polar(1.0, d.frame_phase_rad[i]);
    d.x[i] = cplx(r.cx[i], -r.sx[i]) * rot;
    d.y[i] = cplx(r.cy[i], -r.sy[i]) * rot;
    r.phase[i] += d.frame_phase_rad[i];
  }
}

// White noise from second differences of the slow, derotated envelopes.
double white_noise_v(const std::vector<Run>& runs, const Dataset& d) {
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
  const double noise = median(d2) * 1.482602 / std::sqrt(6.0);
  return noise > 0.0 ? noise : 1e-12;
}

// Temperature reference and the spans of temperature, free-decay a_A^2 and rate.
// Returns the largest |rate| (rad/s).
double measure_spans(const Rows& r, Dataset& d) {
  double tmin = 1e300, tmax = -1e300, amin = 1e300, amax = -1e300, rmin = 1e300, rmax = -1e300;
  for (std::size_t i = 0; i < r.n; ++i) {
    if (r.temp) tmin = std::min(tmin, (*r.temp)[i]), tmax = std::max(tmax, (*r.temp)[i]);
    if (r.exc[i] == 0.0) amin = std::min(amin, r.a2[i]), amax = std::max(amax, r.a2[i]);
    const double rr = r.rate_rad_s(i);
    rmin = std::min(rmin, rr);
    rmax = std::max(rmax, rr);
  }
  d.temp_ref_c = r.temp ? 0.5 * (tmin + tmax) : 0.0;
  d.temp_span_c = r.temp ? tmax - tmin : 0.0;
  d.a2_span_v2 = amax > amin ? amax - amin : 0.0;
  d.rate_span_rad_s = rmax - rmin;
  return std::max(std::abs(rmin), std::abs(rmax));
}

// Block length: enough blocks for the envelope, short enough for the
// fourth-order propagator (|A'| T_block <= 0.2), at most max_blocks blocks.
std::size_t block_length(const std::vector<Run>& runs, double dt, double max_rate,
                         double angular_gain, int max_blocks) {
  std::size_t n_free = 0;
  for (const auto& r : runs) {
    if (!r.exc && r.last - r.first + 1 >= kMinFreeSamples) n_free += r.last - r.first + 1;
  }
  const double a_fast = max_rate * angular_gain + 0.05;
  const auto nb_acc = static_cast<std::size_t>(std::max(1.0, std::floor(0.2 / (a_fast * dt))));
  const std::size_t nb_cost =
      (n_free + static_cast<std::size_t>(max_blocks) - 1) / static_cast<std::size_t>(max_blocks);
  return std::clamp<std::size_t>(nb_cost, 1, nb_acc);
}

// One averaging block of rows [b0, b1].
Block make_block(const Rows& r, const Dataset& d, std::size_t b0, std::size_t b1) {
  Block b;
  b.n = static_cast<double>(b1 - b0 + 1);
  for (std::size_t i = b0; i <= b1; ++i)
    b.t_s += r.t[i] / b.n;
  for (std::size_t i = b0; i <= b1; ++i) {
    const double tau = r.t[i] - b.t_s;
    b.m2 += tau * tau / b.n, b.m3 += tau * tau * tau / b.n, b.m4 += tau * tau * tau * tau / b.n;
    b.x += d.x[i] / b.n;
    b.y += d.y[i] / b.n;
    b.temp_c += r.temp ? (*r.temp)[i] / b.n : 0.0;
    b.rate_rad_s += r.rate_rad_s(i) / b.n;
    b.a2_v2 += r.a2[i] / b.n;
    b.theta_rad += r.theta[i] / b.n;
    b.rot += std::polar(1.0, d.frame_phase_rad[i]) / b.n;
  }
  return b;
}

// Rows of the excitation run `fr` at its end next to the free segment
// (its start when !at_start) whose pump is already off while the run still
// says excitation: a producer that marks a row free only once its whole
// averaging span is (exc stays 1 over the demodulator's span) leaves such
// rows, whose signals have already lost the pump's feedthrough. They are
// neither forced nor free evidence at the edge.
std::size_t pump_off_rows_at_edge(const Rows& r, const Run& fr, bool at_start) {
  if (!r.pump) return 0;
  const std::size_t run_rows = fr.last - fr.first + 1;
  std::size_t k = 0;
  while (k < run_rows && (*r.pump)[at_start ? fr.last - k : fr.first + k] == 0.0)
    ++k;
  return k == run_rows ? 0 : k;  // a run without any pump keeps its rows
}

// The switching edge between free segment `seg_index` and the excitation run
// `fr` next to it (before it when at_start).
void add_edge(const Rows& r, const Run& fr, std::size_t seg_index, bool at_start, Dataset& d) {
  Edge e;
  e.free_segment = seg_index;
  e.at_start = at_start;
  const std::size_t skip = pump_off_rows_at_edge(r, fr, at_start);
  e.pump_off_rows = skip;
  const std::size_t run_rows = fr.last - fr.first + 1 - skip;
  auto row_at = [&](std::size_t j) { return at_start ? fr.last - skip - j : fr.first + skip + j; };
  const std::size_t m = std::min<std::size_t>(kEdgeRows, run_rows);
  double v = 0.0;
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t row = row_at(j);
    e.forced_rows.push_back(row);
    if (r.pump) e.forced_pump_v.push_back(std::abs((*r.pump)[row]));
    v += r.pump ? std::abs((*r.pump)[row]) / static_cast<double>(m) : 1.0 / static_cast<double>(m);
  }
  e.pump_v = v;
  for (std::size_t j = m; j < std::min(run_rows, m + kSlopeRows); ++j) {
    e.slope_rows.push_back(row_at(j));
    if (r.pump) e.slope_pump_v.push_back(std::abs((*r.pump)[row_at(j)]));
  }
  if (m >= 4) d.edges.push_back(e);
}

// A free-decay run averaged into blocks of nb samples, with its edges to the
// neighbouring excitation runs (no gap between them).
void add_free_segment(const Rows& r, const std::vector<Run>& runs, std::size_t ri, std::size_t nb,
                      Dataset& d) {
  const Run& run = runs[ri];
  FreeSegment s;
  s.first_row = run.first;
  s.last_row = run.last;
  s.t0_s = r.t[run.first];
  s.t1_s = r.t[run.last];
  s.first_block = d.blocks.size();
  for (std::size_t b0 = run.first; b0 <= run.last; b0 += nb)
    d.blocks.push_back(make_block(r, d, b0, std::min(run.last, b0 + nb - 1)));
  s.n_blocks = d.blocks.size() - s.first_block;
  const std::size_t seg_index = d.free.size();
  d.free.push_back(s);
  if (ri > 0 && runs[ri - 1].exc && runs[ri - 1].last + 1 == run.first &&
      !r.gap_before[run.first]) {
    add_edge(r, runs[ri - 1], seg_index, true, d);
  }
  if (ri + 1 < runs.size() && runs[ri + 1].exc && !r.gap_before[runs[ri + 1].first]) {
    add_edge(r, runs[ri + 1], seg_index, false, d);
  }
}

}  // namespace

Dataset build_dataset(const recording::Recording& rec, int max_blocks) {
  Dataset d;
  d.f_ref_hz = rec.f_ref_hz();
  d.angular_gain = rec.angular_gain();
  Rows r(rec);
  d.has_pump = r.pump != nullptr;
  d.has_temp = r.temp != nullptr;
  d.has_rate = r.rate != nullptr;
  d.t_s = r.t;
  if (r.n > 0) d.t_mid_s = 0.5 * (r.t.front() + r.t.back());
  const std::vector<Run> runs = cut_runs(r);
  note_gaps(rec, d);
  wave_rows(r);
  derotate(r, runs, d);
  d.noise_v = white_noise_v(runs, d);
  const double max_rate = measure_spans(r, d);
  const double dt = rec.typical_step_s();
  const std::size_t nb = block_length(runs, dt, max_rate, d.angular_gain, max_blocks);
  d.samples_per_block = static_cast<int>(nb);
  for (std::size_t ri = 0; ri < runs.size(); ++ri) {
    const std::size_t len = runs[ri].last - runs[ri].first + 1;
    if (runs[ri].exc && len >= kMinForcedSamples) add_forced_segment(r, runs[ri], dt, d);
    if (!runs[ri].exc && len >= kMinFreeSamples) add_free_segment(r, runs, ri, nb, d);
  }
  if (d.forced_jittery > 0) {
    d.notes.push_back(
        std::to_string(d.forced_jittery) +
        " excitation segment(s) left out: their pump_v jitters from row to row by "
        "more than " +
        std::to_string(kMaxPumpJitter).substr(0, 3) +
        " of its level (an amplitude loop faster than the rows, which alias the "
        "pump: their pump voltage, amplitude and angle ends are not the resonator's)");
  }
  // Hold out every fourth free segment (whole segments), when there are enough.
  if (d.free.size() >= 4) {
    for (std::size_t i = 2; i < d.free.size(); i += 4)
      d.free[i].heldout = true;
  }
  return d;
}

}  // namespace hrg::audit::detail
