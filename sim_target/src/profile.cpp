// SPDX-License-Identifier: MIT
#include "sim_target/profile.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace hrg::sim {

namespace {

void check_increasing(const std::vector<ProfilePoint>& points, const char* what) {
  if (points.empty()) throw std::invalid_argument(std::string(what) + ": no points");
  for (std::size_t i = 1; i < points.size(); ++i) {
    if (!(points[i].t_s > points[i - 1].t_s)) {
      throw std::invalid_argument(std::string(what) + ": times must increase strictly (point " +
                                  std::to_string(i) + ")");
    }
  }
}

}  // namespace

Profile Profile::constant(double value) {
  Profile p;
  p.offset_ = value;
  return p;
}

Profile Profile::steps(std::vector<ProfilePoint> points) {
  check_increasing(points, "steps profile");
  Profile p;
  p.kind_ = Kind::steps;
  p.points_ = std::move(points);
  return p;
}

Profile Profile::ramps(std::vector<ProfilePoint> points) {
  check_increasing(points, "ramps profile");
  Profile p;
  p.kind_ = Kind::ramps;
  p.points_ = std::move(points);
  return p;
}

Profile Profile::sine(double amplitude, double freq_hz, double phase_rad) {
  Profile p;
  p.kind_ = Kind::sine;
  p.amplitude_ = amplitude;
  p.freq_hz_ = freq_hz;
  p.phase_rad_ = phase_rad;
  return p;
}

Profile Profile::table_file(const std::string& path, double scale) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open profile table");
  std::vector<ProfilePoint> points;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    std::string a;
    std::string b;
    if (!(fields >> a)) continue;
    char* end_a = nullptr;
    const double t = std::strtod(a.c_str(), &end_a);
    if (end_a == a.c_str() || *end_a != '\0') {
      if (points.empty() && line_no == 1) continue;  // header line
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": column 1 is not a number");
    }
    char* end_b = nullptr;
    if (!(fields >> b)) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": column 2 is missing");
    }
    const double v = std::strtod(b.c_str(), &end_b);
    if (end_b == b.c_str() || *end_b != '\0' || !std::isfinite(v) || !std::isfinite(t)) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": column 2 is not a number");
    }
    if (!points.empty() && !(t > points.back().t_s)) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": time does not increase");
    }
    points.push_back({t, v * scale});
  }
  if (points.empty()) throw std::runtime_error(path + ": profile table has no rows");
  return ramps(std::move(points));
}

double Profile::derivative(double t_s) const {
  switch (kind_) {
    case Kind::constant:
    case Kind::steps: return 0.0;
    case Kind::sine: {
      const double w = 2.0 * std::numbers::pi * freq_hz_;
      return amplitude_ * w * std::cos(w * t_s + phase_rad_);
    }
    case Kind::ramps: {
      if (t_s < points_.front().t_s || t_s >= points_.back().t_s) return 0.0;
      auto it = std::upper_bound(points_.begin(), points_.end(), t_s,
                                 [](double t, const ProfilePoint& p) { return t < p.t_s; });
      const ProfilePoint& b = *it;
      const ProfilePoint& a = *std::prev(it);
      return (b.value - a.value) / (b.t_s - a.t_s);
    }
  }
  return 0.0;
}

double Profile::integral(double t0_s, double t1_s) const {
  if (kind_ == Kind::constant) return offset_ * (t1_s - t0_s);
  if (kind_ == Kind::sine) {
    const double w = 2.0 * std::numbers::pi * freq_hz_;
    const double base = offset_ * (t1_s - t0_s);
    if (w == 0.0) return base + amplitude_ * std::sin(phase_rad_) * (t1_s - t0_s);
    return base +
           amplitude_ / w * (std::cos(w * t0_s + phase_rad_) - std::cos(w * t1_s + phase_rad_));
  }
  ProfileCursor pieces(this);
  return pieces.integral(t0_s, t1_s);
}

double Profile::next_breakpoint_s(double t_s) const {
  if (kind_ != Kind::steps && kind_ != Kind::ramps) return std::numeric_limits<double>::infinity();
  auto it = std::upper_bound(points_.begin(), points_.end(), t_s,
                             [](double t, const ProfilePoint& p) { return t < p.t_s; });
  return it == points_.end() ? std::numeric_limits<double>::infinity() : it->t_s;
}

bool Profile::varies_between(double t0_s, double t1_s) const {
  switch (kind_) {
    case Kind::constant:
    case Kind::steps: return false;
    case Kind::sine: return amplitude_ != 0.0;
    case Kind::ramps: return value(t0_s) != value(t1_s);
  }
  return true;
}

std::size_t Profile::segment_of(double t_s) const {
  const auto it = std::upper_bound(points_.begin(), points_.end(), t_s,
                                   [](double t, const ProfilePoint& p) { return t < p.t_s; });
  return static_cast<std::size_t>(it - points_.begin());
}

double Profile::value(double t_s) const {
  switch (kind_) {
    case Kind::constant: return offset_;
    case Kind::sine:
      return offset_ + amplitude_ * std::sin(2.0 * std::numbers::pi * freq_hz_ * t_s + phase_rad_);
    case Kind::steps:
    case Kind::ramps: return value_in_segment(t_s, segment_of(t_s));
  }
  return offset_;
}

double ProfileCursor::value_searched(double t_s, bool next_step, double step_s) {
  const Profile& p = *p_;
  switch (p.kind_) {
    case Profile::Kind::constant:
      lo_s_ = -std::numeric_limits<double>::infinity();
      hi_s_ = std::numeric_limits<double>::infinity();
      return p.offset_;
    case Profile::Kind::sine: return sine_value(t_s, next_step, step_s);
    case Profile::Kind::steps:
    case Profile::Kind::ramps:
      if (!(t_s >= lo_s_ && t_s < hi_s_)) {
        const auto& pts = p.points_;
        segment_ = p.segment_of(t_s);
        lo_s_ = segment_ == 0 ? -std::numeric_limits<double>::infinity() : pts[segment_ - 1].t_s;
        hi_s_ =
            segment_ == pts.size() ? std::numeric_limits<double>::infinity() : pts[segment_].t_s;
      }
      return p.value_in_segment(t_s, segment_);
  }
  return p.offset_;
}

bool ProfileCursor::constant_over(double t0_s, double t1_s, double& value) {
  const Profile& p = *p_;
  if (p.kind_ == Profile::Kind::sine) return false;
  value = this->value(t0_s, false, 0.0);  // steps and ramps: finds the segment
  if (p.kind_ == Profile::Kind::constant) return true;
  if (!(t1_s < hi_s_)) return false;
  if (p.kind_ == Profile::Kind::steps) return true;
  // A ramp segment between equal values: a + u (b - a) = a for every u.
  const auto& pts = p.points_;
  return segment_ == 0 || segment_ == pts.size() || pts[segment_ - 1].value == pts[segment_].value;
}

double ProfileCursor::piece_end_s(double t_s) {
  if (p_->kind_ == Profile::Kind::sine) return -std::numeric_limits<double>::infinity();
  value(t_s, false, 0.0);  // constant, steps and ramps: finds the segment
  return hi_s_;
}

double ProfileCursor::integral(double t0_s, double t1_s) {
  const Profile& p = *p_;
  if (p.kind_ == Profile::Kind::constant || p.kind_ == Profile::Kind::sine) {
    return p.integral(t0_s, t1_s);
  }
  // Piecewise: constant (steps) or linear (ramps) between corners.
  double sum = 0.0;
  double t = t0_s;
  while (t < t1_s) {
    // The piece's end is Profile::next_breakpoint_s(t), found from the cache.
    const double e = std::min(t1_s, piece_end_s(t));
    if (p.kind_ == Profile::Kind::steps) {
      sum += value(0.5 * (t + e), false, 0.0) * (e - t);
    } else {
      // value(t) first: it moves the cursor to t's piece before e is read.
      const double a = value(t, false, 0.0);
      sum += 0.5 * (a + value(e, false, 0.0)) * (e - t);
    }
    t = e;
  }
  return sum;
}

double ProfileCursor::sine_value(double t_s, bool next_step, double step_s) {
  const Profile& p = *p_;
  const double w = 2.0 * std::numbers::pi * p.freq_hz_;
  if (anchored_ && next_step && step_s == step_s_ && rotations_ < kReanchorSteps) {
    const double s = sin_ * rot_cos_ + cos_ * rot_sin_;
    cos_ = cos_ * rot_cos_ - sin_ * rot_sin_;
    sin_ = s;
    ++rotations_;
  } else {
    const double phase = w * t_s + p.phase_rad_;
    sin_ = std::sin(phase);
    cos_ = std::cos(phase);
    if (!anchored_ || step_s != step_s_) {
      step_s_ = step_s;
      rot_sin_ = std::sin(w * step_s);
      rot_cos_ = std::cos(w * step_s);
    }
    rotations_ = 0;
    anchored_ = true;
  }
  return p.offset_ + p.amplitude_ * sin_;
}

}  // namespace hrg::sim
