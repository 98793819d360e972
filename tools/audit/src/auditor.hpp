// SPDX-License-Identifier: MIT
#pragma once

// The audit's steps (run_audit): the Auditor holds the recording's dataset
// and what each step leaves for the next. Private to tools/audit/src; its
// members are defined by concern:
//   audit.cpp                 the fitted states, the baseline and run()
//   segment_weights.cpp       block noise, the excitation segments' weights
//                             (frequency, balance, angle drift), slow noise
//   segment_pulls.cpp         the drive feedthrough's pulls taken off the
//                             segments before selection
//   forward_selection.cpp     forward selection and the runner-up's retest
//   effect_checks.cpp         drop-unneeded, constancy, thermal vs drift
//   residual_description.cpp  the description of what the catalogue leaves
//   findings.cpp              the findings' weighing and claiming
//   verdict.cpp               the data, baseline, locations and verdict

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include "audit/audit.hpp"
#include "audit/plots.hpp"
#include "dataset.hpp"
#include "effect_params.hpp"
#include "fit.hpp"
#include "model.hpp"
#include "noise_model.hpp"
#include "selection.hpp"

namespace hrg::audit::detail {

constexpr double kPi = std::numbers::pi;
constexpr double kRadToDeg = 180.0 / kPi;

// Segments the balance and the angle drift need: their scatter beyond the
// noise is measured after three shapes are fitted, and with fewer than 7
// degrees of freedom it is not known to within a factor of two (a recording
// of six held segments then shows any control-force residual as a gap).
constexpr std::size_t kBalanceMinSegments = 10;

// Number of shapes forced_scatter takes out of n segments (segment_weights.cpp).
int forced_shapes(std::size_t n, bool phase_shapes);

struct State {
  Mask mask{};
  FitResult fit;
  std::vector<double> res;
  double kappa = 1.0;
  ArNoise ar;  // AR noise model of the residuals (tests against this state)
  bool feedthrough = false;
};

// Effects taken by the forward selection, in the order they were taken.
struct Chosen {
  Effect effect;
  double dbic = 0.0;
  double dchi = 0.0;  // chi^2 removed by it when it was added
  // Set by weigh_findings(): value, 1-sigma (catalogue unit) and the share of
  // the baseline's misfit it removes given everything else (-1: edges).
  double value = 0.0, sigma = 0.0, fraction = 0.0;
  bool unique_checked = false;  // removed_chi2 from a drop-one refit
  double unique_dchi = -1.0;    // chi^2 (whitened) it removes given everything else
  double removed_chi2 = 0.0;    // chi^2 (unwhitened) it removes given everything else
  // The parts of removed_chi2 on the observation groups (Auditor::group_chi2).
  std::array<double, 4> removed_groups{};
};

// One candidate added to the current model.
struct Candidate {
  Effect e;
  State s;
  double dbic;
  double value, sigma;
};

// Per observation group (free decays, the excitation segments' frequency,
// balance and angle drift): whether the final model leaves structure there,
// and the baseline's misfit beyond the noise there. The free decays' come
// from the structure test (their noise is what the final model leaves when
// no structure is left); an excitation group with kBalanceMinSegments
// observations or more is left above unexplained_ratio x its count, and its
// noise is then its count, else what the final model leaves there.
struct GroupMisfit {
  std::array<bool, 4> left{};
  std::array<double, 4> excess{};
};

// The audit of one recording: run() takes the steps in order.
class Auditor {
 public:
  Auditor(const recording::Recording& rec, const AuditOptions& opt)
      : opt_(opt), d_(build_dataset(rec, opt.max_blocks)) {}

  AuditResult run(PlotData* plot);

 private:
  double n_free_res() const { return 4.0 * static_cast<double>(n_blocks_fit_); }
  bool testable(Effect e) const;
  State fit_state(const Mask& mask, const Params& start, bool feedthrough, int max_iterations = 30);
  double ln_neff(const State& s) const {
    return std::log(std::max(10.0, s.kappa * static_cast<double>(s.fit.n_res)));
  }
  // chi^2 that `next` removes from `cur`: with AR whitening both residuals
  // are whitened by the noise model of `next` (the model under test: with the
  // structure it explains taken out, what is left is the noise), otherwise
  // counted at the smaller effective sample fraction.
  double delta_chi2(const State& cur, const State& next) const {
    if (opt_.ar_whitening)
      return whitened_chi2(d_, cur.res, next.ar) - whitened_chi2(d_, next.res, next.ar);
    return std::min(cur.kappa, next.kappa) * (cur.fit.chi2 - next.fit.chi2);
  }
  double delta_bic(const State& cur, const State& next, int extra) const {
    return delta_chi2(cur, next) - extra * ln_neff(next);
  }
  double heldout_rms(const Mask& mask, const Params& start);
  double rms_v(const State& s) const;
  double free_chi2(const State& s) const;  // chi^2 of the free-decay samples alone
  // chi^2 of the excitation-segment observations over their count (0: fewer
  // than kBalanceMinSegments).
  double forced_ratio(const State& s) const;
  double slow_noise_factor(const State& s) const;
  // Residual counts and chi^2 of the observation groups: the free decays,
  // the excitation segments' frequencies, their amplitude balance and their
  // pattern-angle drift.
  std::array<double, 4> group_counts() const;
  std::array<double, 4> group_chi2(const std::vector<double>& res) const;

  // Steps of run(), in order.
  Params start_params() const;
  Mask baseline_mask() const;
  State fit_baseline(AuditResult& out);
  State adopt_block_noise(const Mask& base, State cur, AuditResult& out);
  void remove_feedthrough_pull(const State& cur, AuditResult& out);
  void remove_pump_phase_pull(const State& cur, AuditResult& out);
  void remove_angle_pull(AuditResult& out);
  void remove_frequency_pull(const State& cur, const FeedStat& ft, AuditResult& out);
  State weight_forced_segments(const Mask& base, State cur, AuditResult& out);
  double forced_extra2(const Params& p) const;
  State reweight_forced_segments(const State& baseline, State full);
  double forced_scatter(const std::vector<double>& fr, int p, double nu_per_s) const;
  void weight_balance(AuditResult& out);
  double balance_scatter(const std::vector<std::size_t>& use, double& se2) const;
  void remove_balance_pull(const std::vector<std::size_t>& use, AuditResult& out);
  void weight_angle(const std::vector<std::size_t>& use);
  void describe_data(AuditResult& out) const;
  std::vector<Candidate> score_candidates(const State& cur, const std::vector<Chosen>& chosen,
                                          bool first_step, AuditResult& out);
  void retest_runner_up(const std::vector<Candidate>& cands, AuditResult& out);
  void forward_select(State& cur, std::vector<Chosen>& chosen, AuditResult& out);
  void test_feedthrough(const State& cur, const FeedStat& ft, std::vector<Chosen>& chosen,
                        AuditResult& out);
  State describe(const State& cat, AuditResult& out);
  void finish_description(const State& cur, double heldout_after, AuditResult& out);
  State drop_unneeded(State full, std::vector<Chosen>& chosen, AuditResult& out);
  State test_constancy(State full, std::vector<Chosen>& chosen, AuditResult& out);
  void test_thermal_vs_drift(const State& full, std::vector<Chosen>& chosen, AuditResult& out);
  double temp_time_correlation() const;
  GroupMisfit group_misfit(const State& full, bool structure_left, double excess_free) const;
  void weigh_findings(const State& full, const FeedStat& ft, std::vector<Chosen>& chosen,
                      bool structure_left, AuditResult& out);
  void report_baseline(const State& baseline, const State& cur, bool any_chosen, AuditResult& out);
  void claim_findings(const State& cur, const std::vector<Chosen>& chosen, AuditResult& out);
  void report_locations(const State& baseline, const FeedStat& ft, AuditResult& out);
  void set_verdict(const State& cur, const FeedStat& ft, bool structure_left, AuditResult& out);

  AuditOptions opt_;
  Dataset d_;
  EvalOptions eo_;
  std::size_t n_blocks_fit_ = 0;
  double baseline_chi2_ = 0.0, baseline_n_ = 0.0;  // the baseline's chi^2 and residual count
  double baseline_free_chi2_ = 0.0;                // its chi^2 on the free decays alone
  std::vector<double> baseline_res_;               // its residuals
  std::vector<const GenericTerm*> described_;      // terms of out.description, in order
  Params start_balance_{};   // the free-decay baseline the balance starts from
  bool confounded_ = false;  // a thermal effect and a drift in time cannot be told apart
  // The drive feedthrough the switch-offs show against the baseline (Re, Im
  // of c_x, c_y), when they show one (remove_feedthrough_pull).
  bool ft_shown_ = false;
  std::array<double, 4> ft_c_{};
  // The excitation segments' frequency scatter beyond their white noise
  // (rad^2/s^2) in their weights (weight_forced_segments).
  double forced_extra2_ = 0.0;
};

}  // namespace hrg::audit::detail
