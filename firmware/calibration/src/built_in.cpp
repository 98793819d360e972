// SPDX-License-Identifier: MIT
#include "firmware/calibration_constant.hpp"

namespace hrg::fw {

// In flash on bare metal: the image's own calibration.
const Calibration& built_in_calibration() { return kBuiltInCalibration; }

}  // namespace hrg::fw
