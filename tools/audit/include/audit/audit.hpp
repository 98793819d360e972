// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <string>
#include <vector>

#include "recording/recording.hpp"

// `hrg audit`: fits the seed's averaged resonator model (docs/physics.md) to a
// recording by output error, then extends it with the effects of
// docs/effects-catalog.md one at a time (forward selection, BIC at the
// effective sample count, held-out segments) and reports what physics the
// recording needs that the baseline leaves out. Host-only.
namespace hrg::audit {

enum class Effect {
  pickoff_gain_mismatch,
  pickoff_phase_mismatch,
  pickoff_misalignment,
  duffing_stiffness,
  nonlinear_damping,
  thermal_frequency,
  thermal_damping,
  electrostatic_spring,
  drive_feedthrough,
  gap_harmonics,
};
inline constexpr int kEffectCount = 10;

struct EffectInfo {
  Effect effect;
  const char* id;                     // catalogue id
  const char* param;                  // catalogue parameter name
  const char* unit;                   // catalogue unit
  const char* explanation;            // one plain sentence of physics
  const char* separating_experiment;  // what tells it from its confusable partners
};
const EffectInfo& effect_info(Effect e);
const std::array<EffectInfo, kEffectCount>& effect_table();

struct AuditOptions {
  // Largest number of averaging blocks over all free-decay samples: bounds the
  // cost for long recordings while the slow envelope keeps its information.
  int max_blocks = 12000;
  // Evidence needed to accept an effect (delta BIC at the effective sample count).
  double min_delta_bic = 10.0;
  // Two candidates whose delta BIC differ by less than this are not told apart.
  double ambiguity_bic = 6.0;
  // Residual variance over high-frequency noise variance above which the
  // remaining structure is called unexplained.
  double unexplained_ratio = 1.5;
  // A catalogue finding must stand this many of its standard deviations away
  // from zero and, with structure left (the excitation segments' included)
  // and always for an effect seen only on the excitation segments, remove at
  // least this share of the baseline's misfit beyond the noise (with
  // structure left on the excitation segments alone, an effect with most of
  // its evidence on the free decays: of theirs).
  double min_significance = 5.0;
  double min_explains_fraction = 0.2;
  // Evidence for a generic description term (delta BIC): a search over many
  // shapes needs more than one catalogue candidate.
  double min_description_bic = 20.0;
  // A description term must remove at least this share of the baseline's
  // misfit beyond the noise (chi^2 minus its count; all of it when the
  // baseline is at the noise): a trace of model error beside a large
  // catalogue effect is not described (it stays in the locations).
  double min_description_share = 0.05;
  // With noise slower than the AR model follows (its variance at long lags
  // above 1.2x the white level), a term must also lower the mean-square
  // residual by this share of the noise variance, its slow part included.
  double min_description_fall = 0.1;
  int max_description_terms = 3;
  // Noise model of the tests: residuals whitened by an AR model per channel
  // (true) or white residuals counted at the effective sample count from
  // their integrated autocorrelation (false).
  bool ar_whitening = true;
};

struct Location {
  std::string signal;
  std::string where;
  double score = 0.0;
};

struct Finding {
  Effect effect;
  double value = 0.0;  // catalogue parameter, catalogue unit
  double sigma = 0.0;  // 1-sigma uncertainty, same unit
  double delta_bic = 0.0;
  double heldout_rms_before_v = 0.0;
  double heldout_rms_after_v = 0.0;
  // Share of the baseline's misfit beyond the noise that this effect alone
  // removes given everything else accepted (drop-one refit); the free
  // decays' noise is chi^2 = n, or what the final model leaves there when it
  // leaves no structure on them (README step 7).
  double explains_fraction = 0.0;
  double significance = 0.0;  // |value| / sigma
  std::string impact;         // in gyro units
  // drive_feedthrough only: c_x and c_y as re/im pairs (V/V) against the wave
  // phase at the edge (the recording carries the pump amplitude, not its phase).
  std::array<double, 4> feedthrough_re_im{};
  // gap_harmonics only (value is |eps| = hypot(eps_p, eps_q)): eps_p, eps_q
  // and their 1-sigma.
  std::array<double, 4> gap_eps_pq_sigma{};
};

// One term of the generic description of structure no catalogue effect names.
struct DescriptionTerm {
  std::string term;  // generic shape, e.g. gain_ratio_drift (never a catalogue id)
  std::string text;  // plain words and numbers
  double delta_bic = 0.0;
  double explains_fraction = 0.0;
};

// What the catalogue cannot name, described (verdict `unexplained`).
struct Description {
  std::vector<DescriptionTerm> terms;
  double fit_rms_before_v = 0.0;  // catalogue model, all free-decay samples
  double fit_rms_after_v = 0.0;   // with the description
  double heldout_rms_before_v = 0.0;
  double heldout_rms_after_v = 0.0;
};

struct Alternative {
  Effect effect;
  double value = 0.0;
  double delta_bic = 0.0;
  std::string note;
};

// Evidence for one candidate added to the baseline alone (first selection step).
struct CandidateScore {
  Effect effect;
  bool testable = false;  // false when the recording lacks what it needs (e.g. temp_c)
  double value = 0.0;
  double sigma = 0.0;  // Cramer-Rao-like 1-sigma from the fit (effective samples)
  double delta_bic = 0.0;
  // Detection threshold of this recording's design and noise: 5 sigma of the
  // effect's own estimate, or the strength at which its expected delta BIC
  // turns positive if that is larger.
  double threshold = 0.0;
};

struct BaselineParams {
  double f_hz = 0.0;
  double nu_per_s = 0.0;
  double dmu = 0.0;
  double theta_mu_deg = 0.0;
  double split_hz = 0.0;
  double theta_w_deg = 0.0;
  double angular_gain = 0.0;
  double q = 0.0;
};

struct AuditResult {
  std::string verdict;  // consistent | explained | ambiguous | unexplained
  BaselineParams baseline;
  double heldout_rms_v = 0.0;        // baseline, held-out free-decay segments
  double heldout_rms_final_v = 0.0;  // selected model, same segments
  double fit_rms_before_v = 0.0;     // baseline, all free-decay samples
  double fit_rms_after_v = 0.0;      // selected model
  double noise_v = 0.0;              // white-noise level from second differences
  double temp_ref_c = 0.0;           // T0 of the thermal effects (mid-range of temp_c)
  double n_effective = 0.0;
  std::vector<Location> locations;
  std::vector<Finding> findings;
  std::vector<Alternative> alternatives;
  std::vector<CandidateScore> candidates;
  Description description;  // empty unless structure is left that the catalogue cannot name
  std::string ambiguity_experiment;
  std::string unexplained_note;
  std::vector<std::string> notes;  // gaps, skipped tests, ...
  // The rule a finding met (README step 7), with this run's thresholds.
  std::string acceptance_rule;
  int free_segments = 0;
  int forced_segments = 0;
  // Excitation segments left out because their pump_v jitters from row to
  // row (the rows alias the pump; a note says why).
  int forced_segments_left_out = 0;
  // The excitation segments' ringing frequency against the baseline's free
  // decays: weighted mean offset and its 1-sigma (Hz), mean pump_v^2 (V^2);
  // 0 without excitation segments. A pump at its ideal phase pulls nothing.
  double excitation_offset_hz = 0.0;
  double excitation_offset_sigma_hz = 0.0;
  double excitation_mean_pump_v2 = 0.0;
  int heldout_segments = 0;
  int blocks = 0;
  int samples_per_block = 1;
};

// Runs the audit. Throws std::runtime_error when the recording has too little
// free decay to fit the baseline.
struct PlotData;
// `plot`, when given, receives the per-block series for write_plots().
AuditResult run_audit(const recording::Recording& rec, const AuditOptions& opt = {},
                      PlotData* plot = nullptr);

// The JSON contract of issue 8 (plus a few extra keys).
std::string to_json(const AuditResult& r);
// The human report: verdict first.
std::string to_text(const AuditResult& r, const std::string& source);

}  // namespace hrg::audit
