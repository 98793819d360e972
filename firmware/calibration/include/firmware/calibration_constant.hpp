// SPDX-License-Identifier: MIT
#pragma once

// The calibration built into the image (the bare-metal build has no file
// system): the identity unless the build names a header that defines
// `kBuiltInCalibration` (cmake -DHRG_CALIBRATION_HEADER=/path/gyro_1234.hpp,
// written from the gyro's TOML by `hrg calibration-check FILE --header OUT`).
// Checked at compile time: a constant outside the physical ranges does not
// build. Internal linkage (constexpr, not inline): each translation unit
// sees the one its build names.

#include "firmware/calibration.hpp"

#if defined(HRG_CALIBRATION_HEADER)
#include HRG_CALIBRATION_HEADER
#else
namespace hrg::fw {
constexpr Calibration kBuiltInCalibration = kIdentityCalibration;
}  // namespace hrg::fw
#endif

namespace hrg::fw {
static_assert(first_out_of_range(kBuiltInCalibration) < 0,
              "the built-in calibration has a field outside its physical range");
// The same constant, out of line (one copy in flash).
const Calibration& built_in_calibration();
}  // namespace hrg::fw
