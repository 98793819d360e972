// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>

#include "firmware/estimator_health.hpp"
#include "firmware/mode.hpp"

namespace hrg::fw {

// Interval excitation shutdown (seed section 5): short free-decay windows feed
// the identification; they should be spread evenly over the 4 theta_A circle,
// since an uneven spread acts like extra weights in the least squares.
struct WindowConfig {
  uint32_t length_frames = 100;       // excitation off per window (base frames)
  uint32_t period_frames = 500;       // minimum spacing between window starts
  uint32_t max_wait_frames = 5000;    // open anyway after this long (a bin may never be reached)
  uint32_t bins = 16;                 // 4 theta_A bins over the full circle (<= kMaxBins)
  uint32_t windows_per_bin = 4;       // cap: the campaign ends when every bin holds this many
  uint32_t min_windows_per_bin = 0;   // the estimator's word counts once every bin has this many
  double condition_good = 1.0e4;      // estimator condition number that ends the campaign
  double coverage_good = 0.9;         // estimator coverage (0..1) that ends the campaign
  bool rotate_on_static_base = true;  // command the pattern angle to fill empty bins
  double static_rate_rad_s = 1.0e-3;  // |theta_A'| below this is a static base
  // After the campaign the still-base test reads theta_A' averaged
  // (exponentially) over this many frames (0 or 1: as given). The output's
  // rate over a few frames is noisier on a still table than
  // static_rate_rad_s, so unaveraged the base is never still for a window
  // period and the still-base check never comes.
  uint32_t still_rate_average_frames = 0;
  uint32_t refresh_period_frames = 0;  // restart the campaign after this long (0: never)
  uint32_t check_period_frames = 0;    // after the campaign, a check window this often (0: none)
  // The first check of a model newly in force (the campaign's end, a model
  // or calibration changed: model_changed()) comes this long after it (base
  // frames; 0: the check period), the check period only between later
  // checks. A model is checked as soon as it is applied: with a 10 min
  // period, a campaign's model would otherwise go unchecked (and unreported
  // as valid) for 10 min. Counted from the last window's start at the
  // campaign's end (the model is that window's fit), never closer than the
  // window period.
  uint32_t first_check_delay_frames = 0;
  // Continued identification in operation: after the campaign, windows also
  // open whenever one more keeps the run's excitation-off share at or below
  // this (0: only the check windows above). The check windows count in it,
  // and the gyro folds them into the identification (GyroConfig::
  // continue_identification), so one window is both a check and new data.
  double operation_duty = 0.0;
  // Length of the windows after the campaign (0: length_frames). The decay
  // information of a window grows as its length cubed, so at a given duty
  // longer windows identify faster (a 10 s window: 8x a 5 s one's for 2x the
  // time), as long as the amplitude lost in one stays within what the AGC
  // recovers.
  uint32_t operation_length_frames = 0;
  // Length of the check windows (0: the operation windows' length). Checks
  // are forced every check period whatever the duty, so long operation
  // windows want short checks (a 30 s check every 10 min alone is 5 %
  // excitation off); a long operation window is a check as well.
  uint32_t check_length_frames = 0;
  // Angle diversity in operation: on a still base the pattern settles at its
  // drift's equilibrium angle, so every operation window would see one
  // 4 theta and inform only nu and one combination of the anisotropy terms.
  // With this set, an operation window due while the pattern sits in a bin
  // that holds more windows than the least-covered ones first walks the
  // pattern to the nearest of those (the forcers turn it; the output is held
  // while it moves, GyroStatus::pattern_control), or opens where it is after
  // max_walk_frames of walking.
  bool rotate_in_operation = false;
  // Longest walk (base frames): 45 deg of pattern angle, the farthest bin of
  // a half circle, at the default forcers' 0.36 deg/s is 125 s.
  uint32_t max_walk_frames = 180000;
};

struct WindowDecision {
  bool open = false;              // start a free-decay window now
  bool close = false;             // end the running window now
  bool pattern_command = false;   // drive the pattern to pattern_target_rad
  double pattern_target_rad = 0;  // theta_A target (physical angle)
};

class WindowScheduler {
 public:
  static constexpr uint32_t kMaxBins = 64;

  explicit WindowScheduler(const WindowConfig& cfg = {});

  // Once per base frame. `theta_rad`: theta_A (unwrapped or not);
  // `theta_rate_rad_s`: its smoothed rate, used to tell a static base.
  // Task context, no allocation.
  WindowDecision step(Mode mode, double theta_rad, double theta_rate_rad_s,
                      const EstimatorHealth& health);

  // The model in force has changed (a calibration applied, a model put back):
  // its first check is due first_check_delay_frames from now. During the
  // campaign nothing changes (the campaign's end counts). Task context.
  void model_changed() {
    check_pending_ = true;
    since_change_ = 0;
  }

  // New window length and period (a host command); coverage, duty and the
  // campaign state are kept. Zero length is taken as one frame.
  void set_timing(uint32_t length_frames, uint32_t period_frames) {
    cfg_.length_frames = length_frames == 0 ? 1 : length_frames;
    cfg_.period_frames = period_frames;
  }

  // 4 theta bin index of a physical angle, 0..bins-1.
  uint32_t bin_of(double theta_rad) const;
  // theta_A nearest to `from_rad` whose 4 theta lies at the centre of `bin`.
  double bin_centre_near(uint32_t bin, double from_rad) const;

  uint32_t bin_count(uint32_t bin) const { return counts_[bin]; }
  uint32_t windows() const { return windows_; }
  bool campaign_done() const { return done_; }
  bool in_window() const { return in_window_; }
  // Share of base frames with excitation switched off by a window, 0..1.
  double excitation_off_fraction() const;
  uint64_t frames() const { return frames_; }
  uint64_t off_frames() const { return off_frames_; }
  const WindowConfig& config() const { return cfg_; }

 private:
  bool under_covered(uint32_t bin) const;
  // Length (frames) of the window due now after the campaign, 0: none.
  uint32_t operation_window_due(bool is_static) const;
  void open(uint32_t bin, uint32_t length_frames, WindowDecision& d);
  uint32_t operation_length() const {
    return cfg_.operation_length_frames != 0 ? cfg_.operation_length_frames : cfg_.length_frames;
  }
  // The settling delay of a model newly in force (frames).
  uint32_t first_check_delay() const {
    return cfg_.first_check_delay_frames != 0 ? cfg_.first_check_delay_frames
                                              : cfg_.check_period_frames;
  }
  uint32_t check_length() const {
    return cfg_.check_length_frames != 0 ? cfg_.check_length_frames : operation_length();
  }
  uint32_t least_covered_bin() const;
  // theta_A of the nearest centre of a least-covered bin.
  double nearest_least_covered_rad(double theta_rad) const;
  // The operation window due now (rotate_in_operation: after the walk).
  void operation_window(double theta_rad, bool is_static, uint32_t length_frames,
                        WindowDecision& d);

  WindowConfig cfg_;
  std::array<uint32_t, kMaxBins> counts_{};
  uint64_t frames_ = 0;
  uint64_t off_frames_ = 0;
  uint32_t since_start_ = 0;
  uint32_t in_window_frames_ = 0;
  uint32_t window_length_ = 1;  // the running window's length (frames)
  uint32_t since_done_ = 0;
  uint32_t window_bin_ = 0;
  uint32_t windows_ = 0;
  bool in_window_ = false;
  bool done_ = false;
  bool static_checked_ = false;  // a check window has run on a still base
  uint32_t static_frames_ = 0;   // frames the base has been still, after the campaign
  bool moving_ = false;          // a commanded pattern move is under way
  double move_target_rad_ = 0.0;
  uint32_t move_frames_ = 0;       // frames of the operation walk under way
  bool check_pending_ = false;     // the model newly in force has had no check yet
  double still_rate_rad_s_ = 0.0;  // theta_A' averaged for the still-base test
  uint32_t since_change_ = 0;      // frames since it went in force (see model_changed)
};

}  // namespace hrg::fw
