// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>

#include "estimator/drift.hpp"

namespace hrg::fw {

// Gyro output in whole-angle mode (physics.md section 3):
//   Omega K = -2 theta_A' + D   =>   angle = -2 (theta_A - theta_A0) / K + integral(D) / K
// where D is the estimator's modelled drift (D_nu + D_w, rad/s in Omega K units),
// integrated by est::DriftCompensator's trapezoid while the output is valid.
// theta_A comes unwrapped from the signal chain (dsp::ChainOutputs::theta_A_rad).
class AngleOutput {
 public:
  static constexpr uint32_t kRateFrames = 10;  // rate = angle change over this many frames

  // `gain_k`: angular gain K (2 x Bryan factor); `frame_s`: base frame period.
  AngleOutput(double gain_k, double frame_s) : k_(gain_k), dt_(frame_s), drift_(gain_k) {}

  // Once per base frame. `theta_rad`: theta_A, unwrapped;
  // `drift_rad_s`: estimated drift D (0 before identification);
  // `valid`: the mode allows a valid output. Task context.
  void update(double theta_rad, double drift_rad_s, bool valid);

  // Starts a new reference: the next update sets theta_A0, the angle keeps its
  // value (used after the pattern was moved on purpose).
  void rereference() { have_ref_ = false; }

  double angle_rad() const { return angle_rad_; }
  double raw_angle_rad() const { return raw_rad_ + raw_base_rad_; }
  double correction_rad() const { return drift_.correction_rad(); }
  double rate_rad_s() const { return rate_rad_s_; }
  double theta_unwrapped_rad() const { return theta_rad_; }
  bool valid() const { return valid_; }
  double gain_k() const { return k_; }

 private:
  double k_;
  double dt_;
  est::DriftCompensator drift_;  // integral of D / K
  double theta_rad_ = 0.0;
  double theta0_ = 0.0;
  double raw_rad_ = 0.0;       // -2 (theta_A - theta_A0) / K since the reference
  double raw_base_rad_ = 0.0;  // raw angle accumulated before the last re-reference
  double angle_rad_ = 0.0;
  double rate_rad_s_ = 0.0;
  std::array<double, kRateFrames> history_{};
  uint32_t head_ = 0;
  uint32_t filled_ = 0;
  bool have_ref_ = false;
  bool valid_ = false;
};

}  // namespace hrg::fw
