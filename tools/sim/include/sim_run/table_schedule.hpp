// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "sim_target/profile.hpp"

namespace hrg::sim_run {

// Ring-up from rest (forcers, then the pump) and lock take about 35 s: the
// rate table stays still this long before it turns.
inline constexpr double kRingUpS = 45.0;

// Case angle of one identification sweep: the pattern (turning at -K/2 of
// the case) goes twice through the 4 theta circle, 180 deg of theta.
inline double sweep_case_rad(double angular_gain) {
  return 2.0 * (std::numbers::pi / 2.0) * 2.0 / angular_gain;
}

// Rate-table schedule, built as a piecewise-linear profile of the case rate.
struct TableSchedule {
  std::vector<sim::ProfilePoint> pts{{0.0, 0.0}};
  double t = 0.0;  // end of the schedule so far, s

  void hold(double dt_s) {
    t += dt_s;
    pts.push_back({t, pts.back().value});
  }
  // Turns the case by `angle_rad` at `rate_rad_s` (its sign is the angle's)
  // with ramps of `ramp_s`.
  void turn(double angle_rad, double rate_rad_s, double ramp_s) {
    const double r = std::copysign(rate_rad_s, angle_rad);
    const double cruise = std::fabs(angle_rad / r) - ramp_s;
    if (cruise < 0) throw std::invalid_argument("schedule: turn too short for its ramps");
    pts.push_back({t + ramp_s, r});
    pts.push_back({t + ramp_s + cruise, r});
    pts.push_back({t + 2 * ramp_s + cruise, 0.0});
    t += 2 * ramp_s + cruise;
  }
  // The case rate, plus a constant (the Earth rate's vertical component).
  sim::Profile profile(double offset_rad_s) const {
    return sim::Profile::ramps(pts).add_offset(offset_rad_s);
  }
};

}  // namespace hrg::sim_run
