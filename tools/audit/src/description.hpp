// SPDX-License-Identifier: MIT
#pragma once

// The generic, physically shaped terms the audit uses to describe structure
// that no catalogue effect names: powers of the amplitude and of the
// temperature offset, drifts in time, harmonics in the pattern angle, the
// excitation state and per-channel pickoff terms. A description is reported
// in plain words and numbers; it never replaces a catalogue name and is
// never written into a calibration.

#include <array>
#include <span>
#include <string>

#include "model.hpp"

namespace hrg::audit::detail {

struct GenericTerm {
  const char* id;
  std::array<int, 2> param_ids;  // model parameters the term frees (started at zero)
  int n_params = 1;
  bool needs_temp = false;
  bool needs_forced = false;
  std::span<const int> params() const {
    return {param_ids.data(), static_cast<std::size_t>(n_params)};
  }
};

// The terms (a fixed table: nothing is allocated).
std::span<const GenericTerm> generic_terms();

// The term in plain words with its fitted numbers (`sigma`: 1-sigma of the
// parameters, same units).
std::string describe_term(const GenericTerm& t, const Dataset& d, const Params& p,
                          const Params& sigma);

}  // namespace hrg::audit::detail
