// SPDX-License-Identifier: MIT
#include "effect_params.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hrg::audit::detail {

namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

}  // namespace

// Model parameter of each effect (-1: the edge statistic instead); the gap
// harmonics have a second one (second_param_of).
int param_of(Effect e) {
  static constexpr int kMap[kEffectCount] = {kGain, kPhase, kMis, kDuff, kNld,
                                             kTf,   kTd,    kEs,  -1,    kGapP};
  return kMap[static_cast<int>(e)];
}

int second_param_of(Effect e) { return e == Effect::gap_harmonics ? kGapQ : -1; }

int n_params_of(Effect e) { return second_param_of(e) >= 0 ? 2 : 1; }

// Effects seen only on the excitation segments (the gap harmonics: the
// pump's balance and drift). Those segments are modelled without the
// firmware's loops, which act on what the pickoffs read: a
// pickoff phase mismatch of 1 deg leaves a 4 theta pattern in the pump that
// reads as eps_p -0.0084 (seed 4 of the default scenario), whether or not
// the free decays leave structure. So beside an effect on the readout (the
// pickoff map, the drive feedthrough) such an effect is weighed against the
// whole misfit; beside effects on the resonator alone, which the segments'
// model holds (a thermal damping acts on the balance through its damping
// scale), it is weighed where its evidence lies, as every other effect: a
// gap of |eps| 0.025 at delta BIC 328 beside a thermal damping on 1800 s of
// the other resonator removed 9 % of the whole misfit (the damping's on the
// free decays) and all of the balance's and the angle drift's.
bool seen_only_on_excitation(Effect e) { return e == Effect::gap_harmonics; }

Mask with_effect(Mask m, Effect e, bool on) {
  for (int i : {param_of(e), second_param_of(e)})
    if (i >= 0) m[static_cast<std::size_t>(i)] = on;
  return m;
}

Params without_effect(Params p, Effect e) {
  for (int i : {param_of(e), second_param_of(e)})
    if (i >= 0) p[static_cast<std::size_t>(i)] = 0.0;
  return p;
}

double to_catalogue(Effect e, double v) {
  if (e == Effect::pickoff_phase_mismatch || e == Effect::pickoff_misalignment) {
    return v * kRadToDeg;
  }
  return v;
}

double effect_value(Effect e, const Params& p) {
  const int j = second_param_of(e);
  const double v = to_catalogue(e, p[static_cast<std::size_t>(param_of(e))]);
  return j < 0 ? v : std::hypot(v, to_catalogue(e, p[static_cast<std::size_t>(j)]));
}

double effect_sigma(Effect e, const Params& sigma) {
  const int j = second_param_of(e);
  const double v = std::abs(to_catalogue(e, sigma[static_cast<std::size_t>(param_of(e))]));
  return j < 0 ? v : std::max(v, std::abs(to_catalogue(e, sigma[static_cast<std::size_t>(j)])));
}

Mask with_term(Mask m, const GenericTerm& t) {
  for (int i : t.params())
    m[static_cast<std::size_t>(i)] = true;
  return m;
}

const GenericTerm* term_of(std::string_view id) {
  for (const auto& g : generic_terms())
    if (std::string_view(g.id) == id) return &g;
  return nullptr;
}

bool acts_on_readout(Effect e) {
  return e == Effect::pickoff_gain_mismatch || e == Effect::pickoff_phase_mismatch ||
         e == Effect::pickoff_misalignment || e == Effect::drive_feedthrough;
}

}  // namespace hrg::audit::detail
