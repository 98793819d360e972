// SPDX-License-Identifier: MIT
// A grid point's figures over its seeds, the bound it is held to and the
// reasons it misses it; the points run on all cores through tools/batch.
#include <cmath>
#include <cstdio>
#include <string>

#include "batch/batch.hpp"
#include "study/point.hpp"

namespace hrg::study {

namespace {

constexpr double kBoundFactor = 2.0;

std::string fmt(const char* f, double a, double b = 0.0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

template <class Get>
double mean_of(const std::vector<SeedResult>& seeds, Get get) {
  double sum = 0.0;
  for (const SeedResult& s : seeds)
    sum += get(s);
  return seeds.empty() ? 0.0 : sum / static_cast<double>(seeds.size());
}

// Mean of a figure over the seeds that have one (>= 0); -1 when none has.
template <class Get>
double mean_measured(const std::vector<SeedResult>& seeds, Get get) {
  double sum = 0.0;
  int n = 0;
  for (const SeedResult& s : seeds) {
    if (get(s) < 0.0) continue;
    sum += get(s);
    ++n;
  }
  return n > 0 ? sum / n : -1.0;
}

// Mean over seeds sample by sample; a negative entry (no bound yet) is left
// out, and a sample none of the seeds has is -1.
std::vector<double> mean_series(const std::vector<SeedResult>& seeds,
                                std::vector<double> SeedResult::*series) {
  std::vector<double> out;
  if (seeds.empty()) return out;
  for (std::size_t i = 0; i < (seeds.front().*series).size(); ++i) {
    double sum = 0.0;
    int n = 0;
    for (const SeedResult& s : seeds) {
      if (i < (s.*series).size() && (s.*series)[i] >= 0.0) {
        sum += (s.*series)[i];
        ++n;
      }
    }
    out.push_back(n > 0 ? sum / n : -1.0);
  }
  return out;
}

// First time from which the mean model ADB stays at or below each threshold.
void reach_times(PointResult& p) {
  for (std::size_t k = 0; k < kThresholdsDph.size(); ++k) {
    std::size_t first_ok = p.model_adb_dph.size();
    for (std::size_t i = p.model_adb_dph.size(); i-- > 0;) {
      if (p.model_adb_dph[i] > kThresholdsDph[k]) break;
      first_ok = i;
    }
    if (first_ok == p.model_adb_dph.size()) continue;
    p.t_reach_s[k] = p.t_s[first_ok];
    p.crb_at_reach_dph[k] = p.crb_adb_dph[first_ok];
  }
}

// Every seed identified its resonator in time and the model in force leaves
// no more than twice its bound: the rest of the compensated ADB is drift the
// resonator model does not hold, the control loops' D_Phi (the pump through
// the ring electrode's gap harmonic, the forcers).
void explain_outside_model(PointResult& p) {
  if (p.model_adb_end_dph < 0.0 || p.crb_adb_end_dph <= 0.0 ||
      p.model_adb_end_dph > kBoundFactor * p.crb_adb_end_dph)
    return;
  std::string what =
      fmt("drift outside the resonator model: the model leaves %.3g deg/h (bound %.3g deg/h)",
          p.model_adb_end_dph, p.crb_adb_end_dph);
  what += fmt(", the bias test shows %.3g deg/h: control-loop drift D_Phi", p.comp_adb_dph);
  if (p.spec.gap > 0.0) what += fmt(" (ring-electrode gap harmonic %.3g)", p.spec.gap);
  what += fmt(", mean D_Phi/K added %.3g deg/h", p.control_drift_mean_dph);
  p.reasons.push_back(what);
}

// The recognised causes of a miss, from what the runs saw.
void explain_miss(const Grid& grid, PointResult& p) {
  if (!p.setup_error.empty()) {
    p.reasons.push_back("not run: " + p.setup_error);
    return;
  }
  if (p.pump_needed_v > p.pump_max_v)
    p.reasons.push_back(
        fmt("pump out of reach: needs %.2f V, limit %.2f V", p.pump_needed_v, p.pump_max_v));
  for (const SeedResult& s : p.seeds) {
    const std::string seed = " (seed " + std::to_string(s.seed) + ")";
    if (!s.locked) {
      p.reasons.push_back("does not lock: never reached operate" + seed);
    } else if (s.comp_parks_degenerate) {
      p.reasons.push_back("no ADB from the bias test: " + s.comp_parks_note + seed);
    } else if (s.t_converged_s < 0.0) {
      // Checked before the bias test: without a model there is nothing to
      // test, and the run needs to be longer for the identification itself.
      p.reasons.push_back(fmt("not converged in run length: identification still running at %.0f s",
                              grid.duration_s) +
                          seed);
    } else if (!s.bias_fit) {
      p.reasons.push_back(fmt("no bias test fits in the run length %.0f s", grid.duration_s) +
                          seed);
    } else if (s.t_converged_s > s.t_bias_start_s) {
      p.reasons.push_back(fmt("bias test started at %.0f s, before the model converged at %.0f s",
                              s.t_bias_start_s, s.t_converged_s) +
                          seed);
    } else if (!s.comp_applied) {
      p.reasons.push_back("compensation withdrawn: " + std::to_string(s.model_checks_failed) +
                          " model checks failed" + seed);
    }
  }
  if (p.reasons.empty()) explain_outside_model(p);
}

}  // namespace

void summarise_point(const Grid& grid, PointResult& p) {
  const auto& s = p.seeds;
  p.raw_adb_dph = mean_measured(s, [](const SeedResult& r) { return r.raw_adb_dph; });
  p.comp_adb_dph = mean_measured(s, [](const SeedResult& r) { return r.comp_adb_dph; });
  p.raw_bias_dph = mean_of(s, [](const SeedResult& r) { return r.raw_bias_dph; });
  p.comp_bias_dph = mean_of(s, [](const SeedResult& r) { return r.comp_bias_dph; });
  p.meas_sigma_dph = mean_of(s, [](const SeedResult& r) { return r.meas_sigma_dph; });
  p.model_adb_dph = mean_series(s, &SeedResult::model_adb_dph);
  p.crb_adb_dph = mean_series(s, &SeedResult::crb_adb_dph);
  p.t_s.clear();
  for (std::size_t i = 0; i < p.model_adb_dph.size(); ++i)
    p.t_s.push_back(static_cast<double>(i + 1) * grid.sample_every_s);
  reach_times(p);
  p.crb_adb_end_dph = p.crb_adb_dph.empty() ? -1.0 : p.crb_adb_dph.back();
  p.model_adb_end_dph = p.model_adb_dph.empty() ? -1.0 : p.model_adb_dph.back();
  p.control_drift_mean_dph =
      mean_of(s, [](const SeedResult& r) { return r.control_drift_mean_dph; });
  const double crb = p.crb_adb_end_dph > 0.0 ? p.crb_adb_end_dph : 0.0;
  p.predicted_adb_dph = std::hypot(crb, p.meas_sigma_dph);
  p.ratio = p.predicted_adb_dph > 0.0 && p.comp_adb_dph >= 0.0
                ? p.comp_adb_dph / p.predicted_adb_dph
                : -1.0;
  // A bias test counts only where every seed measured it with its model
  // converged and in force.
  bool measured = p.setup_error.empty() && !s.empty();
  for (const SeedResult& r : s)
    measured = measured && r.locked && r.bias_fit && !r.comp_parks_degenerate && r.comp_applied &&
               r.t_converged_s >= 0.0 && r.t_converged_s <= r.t_bias_start_s;
  p.meets_bound = measured && p.predicted_adb_dph > 0.0 && p.ratio <= kBoundFactor;
  p.reasons.clear();
  if (!p.meets_bound) explain_miss(grid, p);
}

PointResult run_point(const Grid& grid, std::size_t index, unsigned jobs) {
  PointResult p = prepare_point(grid, point_spec(grid, index));
  if (p.setup_error.empty()) {
    p.seeds = batch::run_indexed(static_cast<std::size_t>(grid.seeds), jobs, [&](std::size_t i) {
      return run_seed(grid, p.spec, static_cast<int>(i));
    });
  }
  summarise_point(grid, p);
  return p;
}

std::vector<PointResult> run_grid(const Grid& grid, unsigned jobs) {
  std::vector<PointResult> points;
  for (std::size_t i = 0; i < grid.points(); ++i)
    points.push_back(prepare_point(grid, point_spec(grid, i)));
  // One flat batch of (point, seed) runs, so that every core stays busy
  // whatever the number of seeds; a point that cannot be set up runs nothing.
  const auto seeds = static_cast<std::size_t>(grid.seeds);
  auto runs = batch::run_indexed(points.size() * seeds, jobs, [&](std::size_t k) {
    const PointResult& p = points[k / seeds];
    if (!p.setup_error.empty()) return SeedResult{};
    return run_seed(grid, p.spec, static_cast<int>(k % seeds));
  });
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].setup_error.empty()) {
      for (std::size_t j = 0; j < seeds; ++j)
        points[i].seeds.push_back(std::move(runs[i * seeds + j]));
    }
    summarise_point(grid, points[i]);
  }
  return points;
}

}  // namespace hrg::study
