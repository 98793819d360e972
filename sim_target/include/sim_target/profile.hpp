// SPDX-License-Identifier: MIT
#pragma once

// A scalar input as a function of simulated time: the input rate Omega(t)
// (rad/s) or the resonator temperature T(t) (degC). SI units; the scenario
// parser converts deg/s and deg/h at the edge.

#include <string>
#include <vector>

namespace hrg::sim {

struct ProfilePoint {
  double t_s = 0.0;
  double value = 0.0;
};

class Profile {
 public:
  enum class Kind { constant, steps, ramps, sine };

  Profile() = default;
  static Profile constant(double value);
  // Holds points[i].value from points[i].t_s until the next point (value
  // before the first point: the first value). Times strictly increasing.
  static Profile steps(std::vector<ProfilePoint> points);
  // Linear between points, held constant outside them. Times strictly increasing.
  static Profile ramps(std::vector<ProfilePoint> points);
  // offset + amplitude sin(2 pi freq t + phase).
  static Profile sine(double amplitude, double freq_hz, double phase_rad);
  // Two-column text table "t_s,value" (comma or blanks; '#' comments; an
  // optional header line), linear between rows like ramps(). Every value is
  // multiplied by `scale` (e.g. deg/s -> rad/s). Throws std::runtime_error
  // naming the file and line on malformed input.
  static Profile table_file(const std::string& path, double scale = 1.0);

  // Adds a constant (e.g. the Earth rate component) to every kind.
  Profile& add_offset(double offset) {
    offset_ += offset;
    return *this;
  }

  double value(double t_s) const;
  // Time derivative (per second); 0 for constant and steps, the segment's
  // slope for ramps (the later segment at a corner).
  double derivative(double t_s) const;
  // Exact integral of the profile over [t0_s, t1_s] (e.g. the input angle).
  double integral(double t0_s, double t1_s) const;
  // The first time after t_s where the profile has a corner (steps: a jump;
  // ramps: a change of slope), +infinity if none. Integrators stop there.
  double next_breakpoint_s(double t_s) const;
  // True when the value changes somewhere in (t0_s, t1_s) without a breakpoint
  // in between (a ramp's slope, a sine).
  bool varies_between(double t0_s, double t1_s) const;
  // True when value() does not depend on time.
  bool is_constant() const {
    return kind_ == Kind::constant || (kind_ == Kind::sine && amplitude_ == 0.0);
  }
  Kind kind() const { return kind_; }
  double offset() const { return offset_; }
  const std::vector<ProfilePoint>& points() const { return points_; }

 private:
  Kind kind_ = Kind::constant;
  double offset_ = 0.0;
  double amplitude_ = 0.0;
  double freq_hz_ = 0.0;
  double phase_rad_ = 0.0;
  std::vector<ProfilePoint> points_;
};

}  // namespace hrg::sim
