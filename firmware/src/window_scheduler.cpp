// SPDX-License-Identifier: MIT
#include "firmware/window_scheduler.hpp"

#include <cmath>
#include <numbers>

namespace hrg::fw {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}  // namespace

WindowScheduler::WindowScheduler(const WindowConfig& cfg) : cfg_(cfg) {
  if (cfg_.bins == 0) cfg_.bins = 1;
  if (cfg_.bins > kMaxBins) cfg_.bins = kMaxBins;
  if (cfg_.length_frames == 0) cfg_.length_frames = 1;
  // The first window may open as soon as the gyro operates.
  since_start_ = cfg_.period_frames;
}

uint32_t WindowScheduler::bin_of(double theta_rad) const {
  double phase = std::fmod(4.0 * theta_rad, kTwoPi);
  if (phase < 0) phase += kTwoPi;
  auto bin = static_cast<uint32_t>(phase / kTwoPi * cfg_.bins);
  return bin >= cfg_.bins ? cfg_.bins - 1 : bin;
}

double WindowScheduler::bin_centre_near(uint32_t bin, double from_rad) const {
  // 4 theta at the bin centre; theta repeats every pi/2.
  const double centre = (static_cast<double>(bin) + 0.5) * kTwoPi / cfg_.bins / 4.0;
  const double quarter = std::numbers::pi / 2.0;
  const double k = std::round((from_rad - centre) / quarter);
  return centre + k * quarter;
}

bool WindowScheduler::under_covered(uint32_t bin) const {
  // Fill evenly: only bins at the current minimum count qualify.
  return counts_[bin] <= counts_[least_covered_bin()];
}

uint32_t WindowScheduler::least_covered_bin() const {
  uint32_t best = 0;
  for (uint32_t b = 1; b < cfg_.bins; ++b) {
    if (counts_[b] < counts_[best]) best = b;
  }
  return best;
}

double WindowScheduler::nearest_least_covered_rad(double theta_rad) const {
  // The pattern walks bin by bin instead of crossing the circle (the forcers
  // turn it slowly).
  const uint32_t least = counts_[least_covered_bin()];
  double best_dist = 1e300;
  double best = theta_rad;
  for (uint32_t b = 0; b < cfg_.bins; ++b) {
    if (counts_[b] != least) continue;
    const double target = bin_centre_near(b, theta_rad);
    if (std::fabs(target - theta_rad) < best_dist) {
      best_dist = std::fabs(target - theta_rad);
      best = target;
    }
  }
  return best;
}

double WindowScheduler::excitation_off_fraction() const {
  return frames_ == 0 ? 0.0 : static_cast<double>(off_frames_) / static_cast<double>(frames_);
}

void WindowScheduler::open(uint32_t bin, uint32_t length_frames, WindowDecision& d) {
  d.open = true;
  in_window_ = true;
  in_window_frames_ = 0;
  window_length_ = length_frames;
  window_bin_ = bin;
  since_start_ = 0;
  moving_ = false;
  move_frames_ = 0;
}

void WindowScheduler::operation_window(double theta_rad, bool is_static, uint32_t length_frames,
                                       WindowDecision& d) {
  const uint32_t bin = bin_of(theta_rad);
  // Once started, the walk holds its target (the pattern's own motion must
  // not make the base look turning) until the pattern reaches a least-covered
  // bin or the longest wait has passed.
  const bool walk = cfg_.rotate_in_operation && (moving_ || is_static) && !under_covered(bin) &&
                    move_frames_ < cfg_.max_walk_frames;
  if (!walk) {
    open(bin, length_frames, d);
    return;
  }
  if (!moving_) {
    move_target_rad_ = nearest_least_covered_rad(theta_rad);
    moving_ = true;
  }
  ++move_frames_;
  d.pattern_command = true;
  d.pattern_target_rad = move_target_rad_;
}

uint32_t WindowScheduler::operation_window_due(bool is_static) const {
  // Continued identification first: as many windows as the duty allows,
  // never closer than the window period. They are the long ones (their
  // decay information grows as the length cubed), and each is also a check.
  if (cfg_.operation_duty > 0.0 && since_start_ >= cfg_.period_frames) {
    const double off_after = static_cast<double>(off_frames_ + operation_length());
    if (off_after <= cfg_.operation_duty * static_cast<double>(frames_ + operation_length())) {
      return operation_length();
    }
  }
  // Check windows: the model in force is tested against new free decays
  // (at whatever turn rate and temperature the gyro now sees) at least every
  // check period, and the first time the base has been still for a window
  // period, at once (what a fit on a turning base absorbs shows on a still
  // one).
  if (cfg_.check_period_frames != 0) {
    if (since_start_ >= cfg_.check_period_frames) return check_length();
    // A model newly in force: its first check after the settling delay.
    if (check_pending_ && since_change_ >= first_check_delay() &&
        since_start_ >= cfg_.period_frames) {
      return check_length();
    }
    if (!static_checked_ && is_static && static_frames_ >= cfg_.period_frames &&
        since_start_ >= cfg_.period_frames) {
      return check_length();
    }
  }
  return 0;
}

WindowDecision WindowScheduler::step(Mode mode, double theta_rad, double theta_rate_rad_s,
                                     const EstimatorHealth& health) {
  WindowDecision d;
  ++frames_;
  if (since_start_ < UINT32_MAX) ++since_start_;
  if (since_change_ < UINT32_MAX) ++since_change_;
  if (cfg_.still_rate_average_frames > 1) {
    still_rate_rad_s_ += (theta_rate_rad_s - still_rate_rad_s_) / cfg_.still_rate_average_frames;
  } else {
    still_rate_rad_s_ = theta_rate_rad_s;
  }
  if (in_window_) {
    ++off_frames_;
    if (mode != Mode::free_decay) {
      // Aborted by a fault or a command: the window does not count.
      in_window_ = false;
      return d;
    }
    if (++in_window_frames_ >= window_length_) {
      in_window_ = false;
      ++counts_[window_bin_];
      ++windows_;
      d.close = true;
    }
    return d;
  }
  const bool estimator_good = counts_[least_covered_bin()] >= cfg_.min_windows_per_bin &&
                              health.solved && health.condition > 0 &&
                              health.condition <= cfg_.condition_good &&
                              health.coverage >= cfg_.coverage_good;
  // The per-bin cap bounds the excitation-off time when the estimator never
  // gets there (e.g. a parameter it cannot see).
  const bool cap_reached = counts_[least_covered_bin()] >= cfg_.windows_per_bin;
  if (!done_ && (estimator_good || cap_reached)) {
    done_ = true;
    since_done_ = 0;
    // The model now applied is the last window's fit: its settling delay
    // counts from that window's start.
    check_pending_ = true;
    since_change_ = since_start_;
  }
  if (done_) {
    const bool refresh =
        cfg_.refresh_period_frames != 0 && ++since_done_ >= cfg_.refresh_period_frames;
    if (!refresh) {
      // In operation: check and continued-identification windows.
      const bool is_static = std::fabs(still_rate_rad_s_) < cfg_.static_rate_rad_s;
      static_frames_ = is_static ? static_frames_ + 1 : 0;
      const uint32_t length = mode == Mode::operate ? operation_window_due(is_static) : 0;
      if (length != 0) {
        operation_window(theta_rad, is_static, length, d);
        static_checked_ = static_checked_ || (d.open && is_static);
        // Every window after the campaign is a check of the model in force.
        check_pending_ = check_pending_ && !d.open;
      } else {
        moving_ = false;  // nothing due (or not operating): no walk under way
        move_frames_ = 0;
      }
      return d;
    }
    counts_ = {};
    done_ = false;
  }
  if (mode != Mode::operate) {
    moving_ = false;
    return d;
  }
  const uint32_t bin = bin_of(theta_rad);
  if (since_start_ >= cfg_.period_frames) {
    const bool is_static = std::fabs(theta_rate_rad_s) < cfg_.static_rate_rad_s;
    if (under_covered(bin) || (!is_static && !moving_ && since_start_ >= cfg_.max_wait_frames) ||
        (is_static && !cfg_.rotate_on_static_base && since_start_ >= cfg_.max_wait_frames)) {
      open(bin, cfg_.length_frames, d);
      return d;
    }
    if (!moving_ && is_static && cfg_.rotate_on_static_base) {
      // The nearest of the least-covered bins. Once started, the move holds
      // its target until a window opens (the pattern's own motion must not
      // make the base look turning).
      move_target_rad_ = nearest_least_covered_rad(theta_rad);
      moving_ = true;
    }
  }
  if (moving_) {
    d.pattern_command = true;
    d.pattern_target_rad = move_target_rad_;
  }
  return d;
}

}  // namespace hrg::fw
