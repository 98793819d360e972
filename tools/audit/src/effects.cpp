// SPDX-License-Identifier: MIT
#include "audit/audit.hpp"

namespace hrg::audit {

namespace {

constexpr std::array<EffectInfo, kEffectCount> kTable{{
    {Effect::pickoff_gain_mismatch, "pickoff_gain_mismatch", "gain", "-",
     "The y pickoff chain has a different gain than x, so the measured amplitude rises and "
     "falls with the pattern angle (a 4-theta pattern in the level, not in the decay rate).",
     "park the pattern at several angles (0, 22.5, 45 deg) and compare the measured amplitude "
     "right after switching off: a gain error changes the level at once, a damping anisotropy "
     "only the decay rate"},
    {Effect::pickoff_phase_mismatch, "pickoff_phase_mismatch", "phase_deg", "deg",
     "The y pickoff chain lags x in phase, so a static false quadrature appears that depends "
     "on the pattern angle and does not grow during a free decay.",
     "run long free decays at a fixed angle: a phase error gives a quadrature that is there "
     "from the first sample, a frequency split one that grows with time"},
    {Effect::pickoff_misalignment, "pickoff_misalignment", "angle_deg", "deg",
     "The y pickoff is not at exactly 45 deg from x, so the measured pattern angle and "
     "amplitude are distorted along a sin-4-theta pattern.",
     "sweep the pattern through a full 4-theta turn under a known rate: misalignment distorts "
     "the readout, a split makes the quadrature grow in time"},
    {Effect::duffing_stiffness, "duffing_stiffness", "hz_per_v2", "Hz/V^2",
     "The resonator stiffens with amplitude (cubic stiffness), so its frequency falls as a "
     "free decay rings down.",
     "repeat a long free decay at two set-point amplitudes with the temperature held: Duffing "
     "follows amplitude squared, thermal drift follows temperature, the spring the pump"},
    {Effect::nonlinear_damping, "nonlinear_damping", "rel_per_v2", "1/V^2",
     "Damping grows with amplitude, so a decay is faster at the start than at the end.",
     "ring down from two set-point amplitudes at the same temperature: nonlinear damping "
     "depends on amplitude, thermal damping on temperature"},
    {Effect::thermal_frequency, "thermal_frequency", "ppm_per_c", "ppm/degC",
     "The resonance frequency follows the resonator temperature.",
     "change the temperature at constant amplitude and pump voltage"},
    {Effect::thermal_damping, "thermal_damping", "rel_per_c", "1/degC",
     "The damping (mean and anisotropy) follows the resonator temperature.",
     "change the temperature at a constant set-point amplitude"},
    {Effect::electrostatic_spring, "electrostatic_spring", "hz_per_v2", "Hz/V^2",
     "The DC part of the pump voltage softens the resonator while the pump is on, so the "
     "frequency with the excitation on differs from the free-decay frequency.",
     "change the pump voltage between excitation segments at the same amplitude: the spring "
     "follows pump voltage squared and vanishes when the pump is off"},
    {Effect::drive_feedthrough, "drive_feedthrough", "v_per_v", "V/V",
     "The pump voltage couples capacitively into the pickoffs, so the measured signals jump "
     "at every switching of the excitation, which no mechanical state can do.",
     "switch the pump at two voltages and look at the step of the demodulated signals at the "
     "switching instant"},
    {Effect::gap_harmonics, "gap_harmonics", "eps", "-",
     "The ring electrode's gap is not uniform (a 4th harmonic eps_p, eps_q of 1/d0^3, the "
     "centring tolerance), so the pump drives the wave harder at some pattern angles: the "
     "pump voltage the amplitude control needs follows 4 theta beyond what the damping "
     "anisotropy asks, and the pump drifts the pattern while it runs.",
     "hold the amplitude with the pump at several parked angles and compare the pump "
     "voltage with the free-decay damping at the same angles: a damping anisotropy shows in "
     "both, the gap only while the pump runs"},
}};

}  // namespace

const std::array<EffectInfo, kEffectCount>& effect_table() { return kTable; }
const EffectInfo& effect_info(Effect e) { return kTable[static_cast<std::size_t>(e)]; }

}  // namespace hrg::audit
