// SPDX-License-Identifier: MIT
#include "report_parts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "dsp/wave_variables.hpp"

namespace hrg::audit::detail {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kRadToDeg = 180.0 / kPi;
}  // namespace

std::string impact_text(const Dataset& d_, const Params& p, Effect e, double v) {
  char buf[256];
  const double k = p[kK] > 0 ? p[kK] : d_.angular_gain;
  double a2 = 0.0, v2 = 0.0;
  for (const auto& f : d_.forced)
    a2 += f.mean_a2, v2 += f.mean_v2;
  if (!d_.forced.empty()) a2 /= static_cast<double>(d_.forced.size());
  if (!d_.forced.empty()) v2 /= static_cast<double>(d_.forced.size());
  if (d_.forced.empty() && !d_.blocks.empty()) a2 = d_.blocks.front().a2_v2;
  const double dw = std::hypot(p[kDwC], p[kDwS]);
  switch (e) {
    case Effect::pickoff_gain_mismatch:
      std::snprintf(buf, sizeof buf,
                    "pattern-angle readout error up to %.3g deg physical (%.3g deg of gyro angle, "
                    "4-theta pattern)",
                    std::abs(v) / 4.0 * kRadToDeg, std::abs(v) / 2.0 / k * kRadToDeg);
      break;
    case Effect::pickoff_phase_mismatch:
      std::snprintf(buf, sizeof buf,
                    "false quadrature a_B/a_A up to %.3g; a quadrature loop nulling it adds an "
                    "angle-dependent bias up to %.3g deg/h through the split",
                    std::abs(v) / 2.0 / kRadToDeg,
                    2.0 * dw * std::abs(v) / 2.0 / kRadToDeg / k * kRadToDeg * 3600.0);
      break;
    case Effect::pickoff_misalignment:
      std::snprintf(buf, sizeof buf,
                    "pattern-angle readout error up to %.3g deg physical (%.3g deg of gyro angle)",
                    std::abs(v), 2.0 * std::abs(v) / k);
      break;
    case Effect::duffing_stiffness:
      std::snprintf(buf, sizeof buf, "%.3g mHz frequency shift at the set-point amplitude",
                    v * a2 * 1e3);
      break;
    case Effect::nonlinear_damping:
      std::snprintf(buf, sizeof buf,
                    "Q lower by %.3g %% at the set point; damping-anisotropy bias scales by "
                    "the same factor (%.3g deg/h)",
                    100.0 * v * a2 / (1.0 + v * a2),
                    v * a2 * std::hypot(p[kDnuC], p[kDnuS]) / k * kRadToDeg * 3600.0);
      break;
    case Effect::thermal_frequency:
      std::snprintf(buf, sizeof buf, "%.3g mHz per degC", v * 1e-6 * d_.f_ref_hz * 1e3);
      break;
    case Effect::thermal_damping:
      std::snprintf(buf, sizeof buf,
                    "Q changes %.3g %% per degC; damping-anisotropy bias %.3g deg/h per degC",
                    -100.0 * v,
                    std::abs(v) * std::hypot(p[kDnuC], p[kDnuS]) / k * kRadToDeg * 3600.0);
      break;
    case Effect::electrostatic_spring:
      std::snprintf(buf, sizeof buf,
                    "%.3g mHz frequency shift while the pump is on (mean pump_v^2 %.3g V^2)",
                    v * v2 * 1e3, v2);
      break;
    case Effect::drive_feedthrough:
      std::snprintf(
          buf, sizeof buf,
          "measured-signal offset %.3g V at the mean pump voltage: false angle/quadrature "
          "up to %.3g deg while the excitation is on",
          v * std::sqrt(v2), v * std::sqrt(v2) / std::sqrt(std::max(a2, 1e-30)) * kRadToDeg / 2.0);
      break;
    case Effect::gap_harmonics:
      // D_Phi = kappa (eps_q/2 cos4th - eps_p/2 sin4th), kappa ~ nu with the AGC holding a_A.
      std::snprintf(buf, sizeof buf,
                    "pump drift D_Phi up to %.3g deg/h (4-theta pattern) while the pump runs",
                    p[kNu] * v / 2.0 / k * kRadToDeg * 3600.0);
      break;
  }
  return buf;
}

void fill_plot(const Dataset& d_, const EvalOptions& eo_, const Params& before, const Params& after,
               PlotData& plot) {
  std::vector<std::array<cplx, 2>> pb, pa;
  std::vector<double> rb, ra;
  EvalOptions all = eo_;
  evaluate(d_, before, all, rb, &pb);
  evaluate(d_, after, all, ra, &pa);
  auto wave = [](cplx x, cplx y) {
    return dsp::wave_variables<double>({x.real(), -x.imag(), y.real(), -y.imag()});
  };
  std::size_t k = 0;
  for (std::size_t si = 0; si < d_.free.size(); ++si) {
    const auto& s = d_.free[si];
    for (std::size_t b = 0; b < s.n_blocks; ++b, k += 4) {
      const auto i = s.first_block + b;
      const Block& bl = d_.blocks[i];
      const auto wm = wave(bl.x, bl.y), wb = wave(pb[i][0], pb[i][1]),
                 wa = wave(pa[i][0], pa[i][1]);
      plot.t_s.push_back(bl.t_s);
      plot.segment.push_back(static_cast<int>(si));
      plot.theta_deg.push_back(bl.theta_rad * kRadToDeg);
      plot.a_meas.push_back(wm.a_A_v), plot.a_before.push_back(wb.a_A_v),
          plot.a_after.push_back(wa.a_A_v);
      plot.q_meas.push_back(wm.a_B_v), plot.q_before.push_back(wb.a_B_v),
          plot.q_after.push_back(wa.a_B_v);
      auto rms4 = [&](const std::vector<double>& r) {
        return std::sqrt(
            (r[k] * r[k] + r[k + 1] * r[k + 1] + r[k + 2] * r[k + 2] + r[k + 3] * r[k + 3]) / 4.0);
      };
      plot.res_before.push_back(rms4(rb));
      plot.res_after.push_back(rms4(ra));
    }
  }
}

// Where each candidate sees the baseline's misfit, with the range of the
// quantity it follows (amplitude, temperature, pump voltage).

void add_candidate_locations(const Dataset& d_, AuditResult& out) {
  double a_lo = 1e300, a_hi = 0.0, t_lo = 1e300, t_hi = -1e300, v_lo = 1e300, v_hi = 0.0;
  for (const auto& b : d_.blocks) {
    a_lo = std::min(a_lo, b.a2_v2), a_hi = std::max(a_hi, b.a2_v2);
    t_lo = std::min(t_lo, b.temp_c), t_hi = std::max(t_hi, b.temp_c);
  }
  for (const auto& f : d_.forced)
    v_lo = std::min(v_lo, f.mean_v2), v_hi = std::max(v_hi, f.mean_v2);
  char buf[200];
  for (const auto& c : out.candidates) {
    // The edge statistic is only meaningful against the final model (locate()).
    if (!c.testable || c.delta_bic <= 0.0 || c.effect == Effect::drive_feedthrough) continue;
    std::string signal, where;
    switch (c.effect) {
      case Effect::pickoff_gain_mismatch:
        signal = "a_A (measured amplitude)",
        where = "4-theta pattern in the level of the free decays";
        break;
      case Effect::pickoff_phase_mismatch:
        signal = "a_B (quadrature)", where = "static quadrature depending on the pattern angle";
        break;
      case Effect::pickoff_misalignment:
        signal = "theta_A, a_A", where = "sin-4-theta distortion of the readout";
        break;
      case Effect::duffing_stiffness:
      case Effect::nonlinear_damping:
        std::snprintf(buf, sizeof buf, "against a_A^2 over %.3g-%.3g V^2 (free decays)", a_lo,
                      a_hi);
        signal = c.effect == Effect::duffing_stiffness ? "wave frequency" : "decay rate",
        where = buf;
        break;
      case Effect::thermal_frequency:
      case Effect::thermal_damping:
        std::snprintf(buf, sizeof buf, "against temperature over %.2f-%.2f degC", t_lo, t_hi);
        signal = c.effect == Effect::thermal_frequency ? "wave frequency" : "decay rate",
        where = buf;
        break;
      case Effect::electrostatic_spring:
        std::snprintf(buf, sizeof buf,
                      "excitation segments against free decays, pump_v^2 %.3g-%.3g V^2", v_lo,
                      v_hi);
        signal = "wave frequency", where = buf;
        break;
      case Effect::drive_feedthrough:
        signal = "cx_v,sx_v,cy_v,sy_v", where = "steps at the switch-offs of exc";
        break;
      case Effect::gap_harmonics:
        std::snprintf(buf, sizeof buf,
                      "4-theta pattern of the pump the amplitude control needs, pump_v^2 "
                      "%.3g-%.3g V^2",
                      v_lo, v_hi);
        signal = "pump_v", where = buf;
        break;
    }
    const bool dup = std::any_of(out.locations.begin(), out.locations.end(),
                                 [&](const Location& l) { return l.where == where; });
    if (!dup)
      out.locations.push_back(
          {signal, where + " (as " + effect_info(c.effect).id + ")", c.delta_bic});
  }
}

}  // namespace hrg::audit::detail
