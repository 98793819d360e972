// SPDX-License-Identifier: MIT
#pragma once

// A scalar input as a function of simulated time: the input rate Omega(t)
// (rad/s) or the resonator temperature T(t) (degC). SI units; the scenario
// parser converts deg/s and deg/h at the edge.

#include <cstddef>
#include <cstdint>
#include <limits>
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
  friend class ProfileCursor;
  // steps/ramps: index of the first point after t_s (0 before the first
  // point, points_.size() from the last one on), and the value there
  // (constant: the value).
  std::size_t segment_of(double t_s) const;
  double value_in_segment(double t_s, std::size_t segment) const;

  Kind kind_ = Kind::constant;
  double offset_ = 0.0;
  double amplitude_ = 0.0;
  double freq_hz_ = 0.0;
  double phase_rad_ = 0.0;
  std::vector<ProfilePoint> points_;
};

inline double Profile::value_in_segment(double t_s, std::size_t segment) const {
  switch (kind_) {
    case Kind::constant: return offset_;
    case Kind::steps:
      return offset_ + (segment == 0 ? points_.front().value : points_[segment - 1].value);
    case Kind::ramps: {
      if (t_s <= points_.front().t_s) return offset_ + points_.front().value;
      if (t_s >= points_.back().t_s) return offset_ + points_.back().value;
      const ProfilePoint& b = points_[segment];
      const ProfilePoint& a = points_[segment - 1];
      const double u = (t_s - a.t_s) / (b.t_s - a.t_s);
      return offset_ + a.value + u * (b.value - a.value);
    }
    case Kind::sine: break;  // not by segment
  }
  return offset_;
}

// A profile sampled at consecutive instants t_k = t_0 + k h (the full-rate
// integrator's step midpoints) without a search or a libm call per sample:
//  - constant, steps, ramps: the segment holding t is kept; while t stays in
//    it, value() is computed by the same expression as Profile::value (same
//    bits).
//  - sine: (sin, cos) of the phase advanced by an exact rotation through
//    2 pi f h, re-anchored from std::sin/std::cos every kReanchorSteps steps
//    (and on any call that is not the next step). Each rotation adds at most
//    4 eps of relative error (amplitude and phase), so
//    |value - Profile::value| <= amplitude (kReanchorSteps 4 eps + 4 eps |phase|)
//    = amplitude (4.4e-13 + 8.9e-16 |2 pi f t + phase|): below 1e-11 of the
//    amplitude for 1 Hz over an hour (tests/sim_target/test_profile_cursor.cpp).
// Holds a pointer to the profile: bind again after the profile moves.
class ProfileCursor {
 public:
  static constexpr uint64_t kReanchorSteps = 1000;

  ProfileCursor() = default;
  explicit ProfileCursor(const Profile* p) { bind(p); }
  void bind(const Profile* p) {
    p_ = p;
    restart();
  }
  const Profile* profile() const { return p_; }
  // Forgets the position: the next call searches or anchors again.
  void restart() {
    lo_s_ = std::numeric_limits<double>::infinity();
    hi_s_ = -std::numeric_limits<double>::infinity();
    anchored_ = false;
  }

  // Value at t_s. `next_step` promises t_s = previous t_s + step_s (with the
  // previous call's step_s), which lets a sine rotate instead of calling sin.
  double value(double t_s, bool next_step, double step_s) {
    if (t_s >= lo_s_ && t_s < hi_s_) return p_->value_in_segment(t_s, segment_);
    return value_searched(t_s, next_step, step_s);
  }
  // True when value() is one and the same number at every instant of
  // [t0_s, t1_s] (t0_s <= t1_s): a constant, a step's hold, a ramp's flat
  // segment; that number goes to `value`. False for a sine (whose cursor
  // state this leaves untouched) and for a span that crosses a breakpoint.
  bool constant_over(double t0_s, double t1_s, double& value);
  // The end of the piece that holds t_s: value() is the one expression of
  // Profile::value over [t_s, end) (a ramp's line, a step's hold; +infinity
  // for a constant and from the last point on), so a caller may evaluate it
  // for many instants in a pass of its own. -infinity for a sine (no piece;
  // its cursor state is left untouched).
  double piece_end_s(double t_s);
  // Profile::integral over [t0_s, t1_s], the same number: steps and ramps
  // piece by piece from the cached segment (a search only where a piece
  // ends, none for a span inside one piece), constant and sine in closed form.
  double integral(double t0_s, double t1_s);

 private:
  double value_searched(double t_s, bool next_step, double step_s);
  double sine_value(double t_s, bool next_step, double step_s);

  const Profile* p_ = nullptr;
  // steps/ramps: the cached segment holds t in [lo_s_, hi_s_).
  std::size_t segment_ = 0;
  double lo_s_ = 0.0;
  double hi_s_ = 0.0;
  // sine: the phase's (sin, cos) and the rotation of one step.
  double sin_ = 0.0;
  double cos_ = 1.0;
  double rot_sin_ = 0.0;
  double rot_cos_ = 1.0;
  double step_s_ = 0.0;
  uint64_t rotations_ = 0;
  bool anchored_ = false;
};

}  // namespace hrg::sim
