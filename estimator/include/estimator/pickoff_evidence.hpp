// SPDX-License-Identifier: MIT
#pragma once

// Which part of a pickoff self-calibration estimate to put in force.
//
// Each part of the map (gain, misalignment, phase) is read with its own noise
// sigma. Applying an estimate x +- sigma leaves an error of ~sigma in the
// correction whatever the truth; leaving it out leaves the truth. Where the
// truth is ~0 (a part the gyro does not have, or one a previous calibration
// already removed), applying the whole estimate only adds its noise: on the
// 4.2 kHz resonator of tools/gregory/README.md at 365 s, ~0.17 deg/h of
// output bias per sigma of gain or misalignment, several times the clean
// gyro's 0.03.
//
// The rule is the posterior mean under a Gaussian prior N(0, tau^2) on the
// part: x tau^2 / (tau^2 + sigma^2). The prior's width is read from the
// estimate itself (E x^2 = tau^2 + sigma^2, so tau^2 = x^2 - sigma^2, 0 when
// negative), which gives x (1 - k sigma^2 / x^2) for x^2 > k sigma^2 and 0
// otherwise, with k = 1. Mean error in sigmas (x ~ N(t, 1), 2e6 draws):
// 0.26 at t = 0 against 0.80 for the whole estimate, at most 1.00 (t ~ 2)
// against 0.80, and 0.85 at t = 5: a true part a few sigma out is kept
// nearly whole, where a significance threshold at 5 sigma would drop it
// (mean error 3.6 sigma at t = 4).
//
// The decision is taken on the whole estimate (the map in force composed
// with the residual the self-calibration reads through it) every round, so
// what an earlier round applied is judged again with every window since
// (its uncertainty carried on: it can be taken back).
//
// Freestanding, no heap.

#include "estimator/pickoff_self_calibration.hpp"

namespace hrg::est {

// The y pickoff map against x: gain mismatch (-), misalignment and phase lag
// (rad), in the calibration's convention (dsp/pickoff_correction.hpp).
struct PickoffMap {
  double gain = 0.0;
  double misalignment_rad = 0.0;
  double phase_rad = 0.0;
};

inline bool operator==(const PickoffMap& a, const PickoffMap& b) {
  return a.gain == b.gain && a.misalignment_rad == b.misalignment_rad && a.phase_rad == b.phase_rad;
}

// The k of the shrinkage: 1, the prior's width read from the estimate (above).
inline constexpr double kEvidenceShrinkK = 1.0;

// x max(0, 1 - k sigma^2 / x^2); 0 for x = 0; x itself when sigma is 0 (an
// exact value). NaN in, NaN out.
double evidence_weighted(double x, double sigma, double k = kEvidenceShrinkK);

// The whole estimate of the map: `in_force` composed with the residual `r`
// read through it (gains compose, misalignments and phases add), each part
// with its 1 sigma (r's, the gain's scaled by 1 + the gain in force; what is
// in force is known exactly). `r` must be ok.
struct PickoffMapEstimate {
  PickoffMap value;
  PickoffMap sigma;
};
PickoffMapEstimate whole_estimate(const PickoffMap& in_force, const PickoffSelfCalResult& r);

// The map to put in force after `r`: each part of the whole estimate
// weighted by its evidence (evidence_weighted). `r` must be ok.
PickoffMap evidence_weighted_map(const PickoffMap& in_force, const PickoffSelfCalResult& r);

// The step from `from` to `to` as a residual result that
// PickoffSelfCalibration::refer_to_applied takes: r with its pickoff parts
// replaced by the step's (gain ratio, angle differences) and its 8theta and
// 12theta level terms by the step's own (level_harmonics_of: the harmonics
// of -ln(1 + rho r - 2 bh s), h_c = rho^2 / 2 - 2 bh^2, h_s = -2 rho bh to
// O(g^3), k_c - i k_s = -(rho + 2i bh)^3 / 12 to O(g^5)). The sigmas stay r's.
PickoffSelfCalResult step_between(const PickoffMap& from, const PickoffMap& to,
                                  const PickoffSelfCalResult& r);

}  // namespace hrg::est
