// SPDX-License-Identifier: MIT
#include "sim_run/analysis.hpp"

#include <cmath>

#include "characterize/allan.hpp"
#include "characterize/harmonic_fit.hpp"

namespace hrg::sim_run {

std::vector<AllanPoint> allan_deviation(std::span<const double> angle, double tau0_s) {
  characterize::AllanOptions octaves;
  for (std::size_t m = 1; angle.size() >= 2 * m + 2; m *= 2)
    octaves.m.push_back(m);
  std::vector<AllanPoint> out;
  for (const auto& p : characterize::allan_from_angle(angle, tau0_s, octaves))
    out.push_back({p.tau_s, p.adev, p.terms});
  return out;
}

double BiasFit::amplitude() const { return std::hypot(a_sin4, b_cos4); }

BiasFit fit_bias_4theta(std::span<const double> theta_rad, std::span<const double> bias) {
  BiasFit f;
  const int orders[] = {4};
  const characterize::HarmonicFit h = characterize::fit_harmonics(theta_rad, bias, orders);
  if (!h.ok) return f;
  f.b0 = h.offset;
  f.sigma_b0 = h.sigma_offset;
  f.a_sin4 = h.harmonics[0].a_sin;
  f.b_cos4 = h.harmonics[0].b_cos;
  f.sigma_a = h.harmonics[0].sigma_a;
  f.sigma_b = h.harmonics[0].sigma_b;
  f.residual_rms = h.residual_rms;
  f.ok = true;
  return f;
}

double slope(std::span<const double> t, std::span<const double> y) {
  const std::size_t n = t.size();
  if (n < 2 || y.size() != n) return 0.0;
  double mt = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) {
    mt += t[i];
    my += y[i];
  }
  mt /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double stt = 0, sty = 0;
  for (std::size_t i = 0; i < n; ++i) {
    stt += (t[i] - mt) * (t[i] - mt);
    sty += (t[i] - mt) * (y[i] - my);
  }
  return stt > 0 ? sty / stt : 0.0;
}

}  // namespace hrg::sim_run
