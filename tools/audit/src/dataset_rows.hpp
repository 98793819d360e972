// SPDX-License-Identifier: MIT
#pragma once

// The recording's rows as build_dataset reads them (dataset.cpp), shared
// with the reduction of its excitation segments (excitation_segments.cpp).
// Private to tools/audit/src.

#include <cstddef>
#include <numbers>
#include <vector>

#include "dataset.hpp"
#include "recording/recording.hpp"

namespace hrg::audit::detail {

// Largest row-to-row jitter of pump_v over an excitation segment, relative to
// its level (pump_jitter). A drive feedthrough closes a path from the pump
// into the measured amplitude within one block; through the amplitude loop's
// proportional term the loop can then oscillate faster than the rows, which
// alias the pump: 0.68-1.01 of its level on the segments that gave a false
// gap harmonic (feedthrough 8e-4 at -45 / 110 deg, default scenario), where a
// loop that holds the amplitude moves its pump by a few percent.
constexpr double kMaxPumpJitter = 0.3;

// Rows of one value of exc between switchings and gaps.
struct Run {
  std::size_t first = 0, last = 0;  // inclusive rows
  bool exc = false;
};

// The column `name`, or nullptr when the recording has none.
inline const std::vector<double>* optional_column(const recording::Recording& rec,
                                                  const char* name) {
  return rec.has_column(name) ? &rec.column(name) : nullptr;
}

// The recording's columns and what the cut derives per row from them.
struct Rows {
  std::size_t n = 0;
  const std::vector<double>& t;
  const std::vector<double>& cx;
  const std::vector<double>& sx;
  const std::vector<double>& cy;
  const std::vector<double>& sy;
  const std::vector<double>& exc;
  const std::vector<double>* pump;
  const std::vector<double>* temp;
  const std::vector<double>* rate;
  const std::vector<double>* fref;
  std::vector<bool> gap_before;
  // Wave variables: continuous pattern angle, wave phase (in the carrier
  // frame once derotated) and a_A^2.
  std::vector<double> theta, phase, a2;

  explicit Rows(const recording::Recording& rec)
      : n(rec.rows()),
        t(rec.column("t_s")),
        cx(rec.column("cx_v")),
        sx(rec.column("sx_v")),
        cy(rec.column("cy_v")),
        sy(rec.column("sy_v")),
        exc(rec.column("exc")),
        pump(optional_column(rec, "pump_v")),
        temp(optional_column(rec, "temp_c")),
        rate(optional_column(rec, "rate_dps")),
        fref(optional_column(rec, "f_ref_hz")),
        gap_before(n, false) {
    for (const auto& g : rec.gaps())
      gap_before[g.row] = true;
  }
  double rate_rad_s(std::size_t i) const {
    return rate ? (*rate)[i] * std::numbers::pi / 180.0 : 0.0;
  }
};

// An excitation run's quiet part reduced to one ForcedSegment (its mean
// frequency and inputs), added to d.forced (excitation_segments.cpp).
void add_forced_segment(const Rows& r, const Run& run, double dt_typ, Dataset& d);

}  // namespace hrg::audit::detail
