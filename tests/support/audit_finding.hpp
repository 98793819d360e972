// SPDX-License-Identifier: MIT
#pragma once

#include "audit/audit.hpp"

namespace hrg::test {

// An accepted finding of the audit as the calibration writer takes it: the
// effect, its catalogue value and 1 sigma (catalogue units); the rest of the
// fit's figures at their defaults.
inline audit::Finding audit_finding(audit::Effect e, double value, double sigma) {
  audit::Finding f;
  f.effect = e;
  f.value = value;
  f.sigma = sigma;
  return f;
}

}  // namespace hrg::test
