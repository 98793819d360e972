// SPDX-License-Identifier: MIT
#include "firmware/angle_output.hpp"

namespace hrg::fw {

void AngleOutput::update(double theta_rad, double drift_rad_s, bool valid) {
  theta_rad_ = theta_rad;
  if (!have_ref_) {
    raw_base_rad_ += raw_rad_;
    raw_rad_ = 0.0;
    theta0_ = theta_rad_;
    have_ref_ = true;
  }
  raw_rad_ = -2.0 * (theta_rad_ - theta0_) / k_;
  // Sign: Omega K = -2 theta' + D, so the drift adds D / K to the rate.
  if (valid) {
    (void)drift_.integrate(drift_rad_s, dt_);
  } else {
    drift_.restart_rate();
  }
  angle_rad_ = raw_base_rad_ + raw_rad_ + drift_.correction_rad();
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
