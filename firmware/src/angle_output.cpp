// SPDX-License-Identifier: MIT
#include "firmware/angle_output.hpp"

#include <cmath>
#include <numbers>

namespace hrg::fw {

void AngleOutput::update(double theta_rad, double drift_rad_s, bool valid) {
  constexpr double kQuarter = std::numbers::pi / 2.0;  // theta_A is defined modulo pi/2
  if (!have_theta_) {
    theta_unwrapped_ = theta_rad;
    have_theta_ = true;
  } else {
    double step = theta_rad - theta_last_wrapped_;
    step -= kQuarter * std::round(step / kQuarter);
    theta_unwrapped_ += step;
  }
  theta_last_wrapped_ = theta_rad;
  if (!have_ref_) {
    raw_base_rad_ += raw_rad_;
    raw_rad_ = 0.0;
    theta0_ = theta_unwrapped_;
    have_ref_ = true;
  }
  raw_rad_ = -2.0 * (theta_unwrapped_ - theta0_) / k_;
  // Sign: Omega K = -2 theta' + D, so the drift adds D / K to the rate.
  if (valid) correction_rad_ += drift_rad_s / k_ * dt_;
  angle_rad_ = raw_base_rad_ + raw_rad_ + correction_rad_;
  history_[head_] = angle_rad_;
  head_ = (head_ + 1) % kRateFrames;
  if (filled_ < kRateFrames) ++filled_;
  if (filled_ >= 2) {
    const uint32_t oldest = filled_ < kRateFrames ? 0 : head_;
    const uint32_t newest = (head_ + kRateFrames - 1) % kRateFrames;
    rate_rad_s_ = (history_[newest] - history_[oldest]) / (dt_ * static_cast<double>(filled_ - 1));
  }
  valid_ = valid;
}

}  // namespace hrg::fw
