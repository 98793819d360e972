// SPDX-License-Identifier: MIT
// What the drive feedthrough of the switch-offs does to the excitation
// segments' observations, taken off them before the selection: the pump
// phase, angle, frequency and balance pulls.
#include "auditor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace hrg::audit::detail {

namespace {

// Most scatter of the excitation segments' frequencies, over their white
// noise (rms), that the feedthrough's measured pull may leave to be taken out
// (Auditor::remove_feedthrough_pull).
constexpr double kPullLeftMax = 1.5;
// Share of the feedthrough's pull that the pump_v column can be wrong by:
// it samples a pump that the firmware's amplitude loop moves within rows
// (c V per row took out ~90 % of the row-to-row motion, Known limits). The
// pull is taken out only where that share stays below the segments' noise;
// a larger pull (the default scenario's 1e-3 V/V: 130x the noise) taken out
// left a false electrostatic spring of 7.3e-7 Hz/V^2 at delta BIC 853.
constexpr double kPumpColumnError = 0.1;

}  // namespace

// A drive feedthrough enters the measured signals, so the measured wave
// phase of an excitation segment is off by Im(V (c_x cos 2 theta + c_y sin
// 2 theta)) / a_A (c in the frame of the wave phase, which the pump follows).
// While the pattern turns (the input rate) or the pump moves, that error
// differs between the segment's ends and pulls its mean frequency by
// Im(c_x) ft_gx + Im(c_y) ft_gy (dataset.hpp): on the averaged model's
// telemetry (feedthrough 2.2e-5 V/V) 4.2e-5 rad/s rms, 4x the segments' noise,
// predicted to 6e-8 rad/s. It is the feedthrough's own forward model of
// those segments, with c from the switch-offs against the baseline (the
// edge statistic of step 3): taken out of the segments' frequencies when
// the switch-offs show a feedthrough, so that what else acts on them (an
// electrostatic spring, a Duffing term) is not hidden under its scatter.
void Auditor::remove_feedthrough_pull(const State& cur, AuditResult& out) {
  if (!d_.has_pump || !testable(Effect::drive_feedthrough)) return;
  const FeedStat ft = feedthrough_stat(d_, cur.fit.p, ln_neff(cur));
  if (!ft.testable || ft.dchi2 - 4.0 * ln_neff(cur) < opt_.min_delta_bic) return;
  ft_shown_ = true;
  ft_c_ = ft.c_re_im;
  remove_pump_phase_pull(cur, out);
  remove_angle_pull(out);
  remove_frequency_pull(cur, ft, out);
}

// The pump follows the measured wave phase, which the feedthrough turns off
// the true one by delta; the pump's parametric drive is then 2 delta off and
// pulls the true frequency by (a_A'/a_A + nu) sin 2 delta (pump_phase_pull,
// model.hpp). Held, the growth is nu and the pull small; on a ring-up from
// rest (a_A small, a_A'/a_A tens of nu) it is the spring's lever arm's
// largest error: on the default scenario with a feedthrough of 8e-4 at -45 /
// 110 deg (seed 1) the ring-up sat -2.08e-4 rad/s off, -1.81e-4 predicted,
// and read as a false electrostatic spring. No free parameter (c is the
// switch-offs'), so it is always taken out when they show a feedthrough.
void Auditor::remove_pump_phase_pull(const State& cur, AuditResult& out) {
  double ss = 0.0, largest = 0.0;
  for (auto& f : d_.forced) {
    const double pull = pump_phase_pull(f, ft_c_, cur.fit.p[kNu]);
    f.freq_rad_s -= pull;
    ss += pull * pull;
    largest = std::max(largest, std::abs(pull));
  }
  char buf[220];
  std::snprintf(buf, sizeof buf,
                "the pump follows the measured wave phase, which the drive feedthrough turns off "
                "the true one: its pull on the excitation segments' frequency (%.2g rad/s rms, "
                "%.2g at most) taken out of them",
                std::sqrt(ss / static_cast<double>(d_.forced.size())), largest);
  out.notes.push_back(buf);
}

// The feedthrough's in-phase part across the vibration turns the measured 2 theta
// by Re(V (c_y cos 2 theta - c_x sin 2 theta)) / a_A (its quadrature part
// moves only a_B, its part along the vibration the phase and a_A), so each
// segment's pattern-angle drift by the change of (Re(c_y) g_x - Re(c_x) g_y)
// / 2 between its end rows over their span. On the default scenario with a
// feedthrough of 8e-4 at -45 / 110 deg (seed 1, every segment kept) it
// predicts -3.04e-4 rad/s for a drift left by the baseline of -3.01e-4, and
// 4.4e-5 for 4.28e-5. No free parameter (c is the switch-offs'), so it is
// always taken out when they show a feedthrough.
void Auditor::remove_angle_pull(AuditResult& out) {
  double ss = 0.0;
  for (auto& f : d_.forced) {
    f.angle_pull_rad_s = 0.5 * (ft_c_[2] * f.ft_ax_per_s - ft_c_[0] * f.ft_ay_per_s);
    ss += f.angle_pull_rad_s * f.angle_pull_rad_s;
  }
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "the drive feedthrough of the switch-offs turns the measured pattern angle of the "
                "excitation segments: %.2g rad/s rms of drift, taken out of them",
                std::sqrt(ss / static_cast<double>(d_.forced.size())));
  out.notes.push_back(buf);
}

// The feedthrough's pull on the segments' measured frequency (step 2).
void Auditor::remove_frequency_pull(const State& cur, const FeedStat& ft, AuditResult& out) {
  std::vector<double> pull;
  double ss = 0.0;
  for (const auto& f : d_.forced) {
    pull.push_back(ft.c_re_im[1] * f.ft_gx_per_s + ft.c_re_im[3] * f.ft_gy_per_s);
    ss += pull.back() * pull.back();
  }
  // The pull is the measurement's alone where the controller acts on the
  // true wave; loops that act on the measured signals (a firmware's PLL,
  // pump phase and quadrature loop) move the driven wave as well, and there
  // the measured pull alone need not leave less scatter. It is taken out
  // only where it does, and leaves the segments at their noise (within
  // kPullLeftMax): where it only lowers the scatter, what is left is the
  // loops' share, which the segments' weights must still hold (no free
  // parameter: c is the switch-offs'); and only where the pump column's
  // error on it stays below the noise (kPumpColumnError).
  const int p = forced_shapes(d_.forced.size(), true);
  std::vector<double> fr = forced_residuals(d_, cur.fit.p);
  const double before = forced_scatter(fr, p, cur.fit.p[kNu]);
  for (std::size_t i = 0; i < fr.size(); ++i)
    fr[i] -= pull[i];
  const double after = forced_scatter(fr, p, cur.fit.p[kNu]);
  const double rms = std::sqrt(ss / static_cast<double>(d_.forced.size()));
  double se2 = 0.0;
  for (const auto& f : d_.forced)
    se2 += f.se_rad_s * f.se_rad_s;
  const auto dof = static_cast<double>(std::max<std::size_t>(1, fr.size() - p));
  char buf[320];
  if (std::getenv("HRG_AUDIT_DEBUG"))
    std::fprintf(stderr, "feedthrough pull %.3g rad/s rms, scatter %.3g -> %.3g, noise %.3g\n", rms,
                 std::sqrt(before / dof), std::sqrt(after / dof),
                 std::sqrt(se2 / static_cast<double>(fr.size())));
  const double noise = std::sqrt(se2 / static_cast<double>(fr.size()));
  if (!(after < before) || std::sqrt(after / dof) > kPullLeftMax * noise ||
      kPumpColumnError * rms > noise) {
    std::snprintf(buf, sizeof buf,
                  "the drive feedthrough's pull on the measured frequency of the excitation "
                  "segments (%.2g rad/s rms) is not taken out: it does not bring their scatter to "
                  "their noise, or the pump column's error on it would not stay below that noise",
                  rms);
    out.notes.push_back(buf);
    return;
  }
  for (std::size_t i = 0; i < pull.size(); ++i)
    d_.forced[i].freq_rad_s -= pull[i];
  std::snprintf(buf, sizeof buf,
                "the drive feedthrough of the switch-offs pulls the measured frequency of the "
                "excitation segments by %.2g rad/s rms; taken out of them",
                rms);
  out.notes.push_back(buf);
}

// The same in-phase part moves the measured a_A along the vibration: ln a_A by
// Re(c_x) g_x + Re(c_y) g_y, so each balance by its change between the
// three-row ends over their span (ft_gx, ft_gy). The firmware's amplitude
// loop holds the measured amplitude, feedthrough included, and moves the
// true vibration by what it takes out of the measured one; so the pull is taken
// out only where that lowers the balances' scatter (on the default
// scenario's 1e-3 V/V row it raised it: chi^2 243 -> 367 on 21).
void Auditor::remove_balance_pull(const std::vector<std::size_t>& use, AuditResult& out) {
  double se2 = 0.0, ss = 0.0;
  const double before = balance_scatter(use, se2);
  std::vector<double> pull(d_.forced.size(), 0.0);
  for (std::size_t i : use) {
    const auto& f = d_.forced[i];
    pull[i] = ft_c_[0] * f.ft_gx_per_s + ft_c_[2] * f.ft_gy_per_s;
    ss += pull[i] * pull[i];
  }
  for (std::size_t i : use)
    d_.forced[i].dlna_per_s -= pull[i];
  const double after = balance_scatter(use, se2);
  const bool keep = after < before;
  if (!keep) {
    for (std::size_t i : use)
      d_.forced[i].dlna_per_s += pull[i];
  }
  char buf[240];
  std::snprintf(buf, sizeof buf,
                "the drive feedthrough's pull on the excitation segments' amplitude balance "
                "(%.2g 1/s rms) %s (their scatter %.3g -> %.3g, weighted by length)",
                std::sqrt(ss / static_cast<double>(use.size())),
                keep ? "is taken out" : "is not taken out: it does not lower their scatter",
                std::sqrt(before / static_cast<double>(use.size())),
                std::sqrt(after / static_cast<double>(use.size())));
  out.notes.push_back(buf);
}

}  // namespace hrg::audit::detail
