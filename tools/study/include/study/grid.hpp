// SPDX-License-Identifier: MIT
#pragma once

// The grid of `hrg study tolerance`: resonators over split, dQ/Q, ring
// electrode gap harmonic and Q (every combination), each run for a number of
// seeds with the main job's schedule (ring-up, rate-table sweep with
// free-decay windows, parked-angle bias test) and the default ADC noise.
// Read from TOML (tools/study/default-grid.toml is the commented default).

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrg::study {

// A grid file the study refuses: the message names file:line: key.
class GridError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Grid {
  std::string source;  // the file it was read from (named in the output)
  // Axes (every combination is a point; split varies fastest, then dQ/Q,
  // then gap, then Q).
  std::vector<double> split_hz;
  std::vector<double> dq_over_q;  // dQ/Q, twice the damping anisotropy dmu
  std::vector<double> gap;        // 4th harmonic of the ring-electrode gap 1/d^3, relative
  std::vector<double> q;
  double gap_axis_deg = 10.0;  // where the gap harmonic points (instrument axes)
  // Runs.
  double duration_s = 3600.0;  // simulated length of every run
  int seeds = 3;               // runs per point, noise seeds base_seed, base_seed + 1, ...
  uint64_t base_seed = 20240531;
  int bias_angles = 16;          // parked angles of the bias test
  double sample_every_s = 10.0;  // the ADB-against-time series' step

  std::size_t points() const { return split_hz.size() * dq_over_q.size() * gap.size() * q.size(); }
};

// One resonator of the grid.
struct PointSpec {
  std::size_t index = 0;
  double split_hz = 0.0;
  double dq_over_q = 0.0;
  double gap = 0.0;
  double q = 0.0;
};

// The point with this index (index < grid.points()).
PointSpec point_spec(const Grid& grid, std::size_t index);

// Parses grid TOML; `source` names it in errors. Throws GridError
// ("source:line: key 'grid.q': what") for malformed text, unknown keys,
// wrong types and values out of range.
Grid parse_grid(const std::string& text, const std::string& source);

// Reads and parses a grid file (GridError also when it cannot be read).
Grid load_grid(const std::string& path);

}  // namespace hrg::study
