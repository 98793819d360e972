// SPDX-License-Identifier: MIT
#pragma once

// The catalogue's effects as model parameters: which parameters an effect
// has, masks and parameter sets with it on or off, and its value and sigma
// in catalogue units.

#include <string_view>

#include "audit/audit.hpp"
#include "description.hpp"
#include "model.hpp"

namespace hrg::audit::detail {

// Model parameter of each effect (-1: the edge statistic instead).
int param_of(Effect e);
// The gap harmonics' second parameter (-1: none).
int second_param_of(Effect e);
int n_params_of(Effect e);
// Effects seen only on the excitation segments (the gap harmonics).
bool seen_only_on_excitation(Effect e);
// Effects on what the pickoffs read (the pickoff map, drive feedthrough).
bool acts_on_readout(Effect e);

// The mask with the effect's parameters on (or off).
Mask with_effect(Mask m, Effect e, bool on = true);
// The parameters with the effect's set to zero.
Params without_effect(Params p, Effect e);
// Internal parameter -> catalogue unit.
double to_catalogue(Effect e, double v);
// The effect's value in catalogue units (a two-parameter effect: its magnitude).
double effect_value(Effect e, const Params& p);
// Its 1-sigma (the magnitude's: the larger of the components' sigmas).
double effect_sigma(Effect e, const Params& sigma);

// The mask with a generic term's parameters on.
Mask with_term(Mask m, const GenericTerm& t);
// The generic term with this id (nullptr: none).
const GenericTerm* term_of(std::string_view id);

}  // namespace hrg::audit::detail
