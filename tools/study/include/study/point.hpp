// SPDX-License-Identifier: MIT
#pragma once

// One grid point of `hrg study tolerance`: the firmware on the simulated
// target (the main job's runner) for each seed, the ADB it reaches against
// the Cramer-Rao bound, and why a point misses the bound when it does.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sim_run/analysis.hpp"
#include "study/grid.hpp"

namespace hrg::study {

// The drift requirements the study times: 3, 0.1 and 0.01 deg/h.
inline constexpr std::array<double, 3> kThresholdsDph{3.0, 0.1, 0.01};

// One run (one seed) of a point. ADB: amplitude of the 4 theta part of the
// bias, deg/h on the input axis.
struct SeedResult {
  uint64_t seed = 0;
  bool locked = false;         // reached operate
  double t_converged_s = -1;   // the identification campaign ended (model applied)
  double t_bias_start_s = -1;  // first parked interval's measurement
  bool bias_fit = false;       // the parked-angle fit had enough angles
  bool comp_applied = false;   // the compensation in force at the end
  uint32_t model_checks_failed = 0;
  double excitation_off = 0;          // fraction of the run
  double control_drift_mean_dph = 0;  // mean D_Phi/K the firmware added over the valid output
  // The parked-angle bias test (IEEE 1431 style), raw and compensated. A
  // park set too narrow for the 4 theta fit (sim_run::BiasFit::degenerate)
  // has no ADB (-1) and its bias is the plain mean over the parks.
  double raw_adb_dph = 0, comp_adb_dph = 0, raw_bias_dph = 0, comp_bias_dph = 0;
  bool raw_parks_degenerate = false, comp_parks_degenerate = false;
  std::string comp_parks_note;  // the compensated park set's geometry when degenerate
  double meas_sigma_dph = 0;    // the compensated fit's own 1-sigma on the ADB (bias test noise)
  // Sampled every Grid::sample_every_s: the model in force against the truth
  // (4 theta amplitude of the resonator drift it leaves, deg/h) and the
  // Cramer-Rao bound of that amplitude for the windows taken (RMS, deg/h).
  std::vector<double> model_adb_dph, crb_adb_dph;
};

struct PointResult {
  PointSpec spec;
  std::string setup_error;   // the point could not be run (e.g. the chain cannot serve it)
  double pump_needed_v = 0;  // pump amplitude that holds the wave on the most damped axis
  double pump_max_v = 0;     // the chain's limit
  std::vector<SeedResult> seeds;
  // Means over seeds; an ADB over the seeds that have one (-1: none has).
  double raw_adb_dph = 0, comp_adb_dph = 0, raw_bias_dph = 0, comp_bias_dph = 0;
  double crb_adb_end_dph = 0;    // Cramer-Rao bound of the model's ADB at the run's end
  double model_adb_end_dph = 0;  // the ADB the model in force leaves at the end (truth)
  double control_drift_mean_dph = 0;
  double meas_sigma_dph = 0;  // bias test noise on the ADB
  // The bound the compensated ADB is held to: the model's CRB and the bias
  // test's own noise in quadrature.
  double predicted_adb_dph = 0;
  double ratio = 0;                  // comp_adb_dph / predicted_adb_dph
  bool meets_bound = false;          // ratio <= 2, on bias tests with the converged model in force
  std::vector<std::string> reasons;  // why it does not (empty when it does)
  // Series (mean over seeds) and the time each threshold is reached for good
  // (-1: not within the run), with the CRB at that time.
  std::vector<double> t_s, model_adb_dph, crb_adb_dph;
  std::array<double, 3> t_reach_s{-1, -1, -1};
  std::array<double, 3> crb_at_reach_dph{-1, -1, -1};
};

// The parked-angle bias test's figures of a run from its raw and
// compensated 4 theta fits (a degenerate park set: no ADB, the plain mean).
void set_bias_test(const sim_run::BiasFit& raw, const sim_run::BiasFit& comp, SeedResult& s);

// Runs seed `seed_index` of the point (the firmware on the simulated target).
// Throws std::invalid_argument when the point cannot be set up.
SeedResult run_seed(const Grid& grid, const PointSpec& spec, int seed_index);

// Everything of a point but its seeds' runs: the set-up check and the pump
// reach; setup_error is filled when run_seed would throw.
PointResult prepare_point(const Grid& grid, const PointSpec& spec);

// Means over the seeds, thresholds, the bound and the reasons.
void summarise_point(const Grid& grid, PointResult& p);

// One point, its seeds on `jobs` threads (tools/batch).
PointResult run_point(const Grid& grid, std::size_t index, unsigned jobs);

// Every point of the grid: all (point, seed) runs on `jobs` threads; the
// result does not depend on `jobs`.
std::vector<PointResult> run_grid(const Grid& grid, unsigned jobs);

}  // namespace hrg::study
