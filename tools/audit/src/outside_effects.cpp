// SPDX-License-Identifier: MIT
// What the benchmark puts into a recording beyond sim_target: coloured
// noise, structure outside the catalogue and a reference that follows the
// resonance.
#include <cmath>
#include <complex>
#include <numbers>
#include <random>

#include "campaign.hpp"

namespace hrg::audit::bench {

namespace {

constexpr double kPi = std::numbers::pi;
using cplx = std::complex<double>;

// 1/f-like noise: a sum of first-order (Lorentzian) processes, one per
// octave from 1 mHz to 50 Hz, each of the same variance v. Their sum has a
// one-sided density close to v / (f ln 2) between the extreme corners; v
// makes it equal to the white noise's density (noise^2 / (fs/2)) at the corner.
void add_flicker(const Scenario& s, recording::Recording& rec, std::mt19937_64& g) {
  const auto& t = rec.column("t_s");
  const std::size_t n = rec.rows();
  if (n < 2) return;
  const double fs = 1.0 / rec.typical_step_s();
  const double white_density = s.noise_v * s.noise_v / (0.5 * fs);
  const double v = white_density * s.flicker_corner_hz * std::log(2.0);
  std::normal_distribution<double> z(0.0, 1.0);
  for (const char* name : {"cx_v", "sx_v", "cy_v", "sy_v"}) {
    auto& col = rec.column(name);
    for (double fc = 1e-3; fc < 0.5 * fs; fc *= 2.0) {
      double x = std::sqrt(v) * z(g);
      for (std::size_t i = 0; i < n; ++i) {
        if (i > 0) {
          const double a = std::exp(-2.0 * kPi * fc * (t[i] - t[i - 1]));
          x = a * x + std::sqrt(v * (1.0 - a * a)) * z(g);
        }
        col[i] += x;
      }
    }
  }
}

// The y pickoff's complex gain at row i for the outside effect.
cplx y_gain(const Scenario& s, double t_rel_h, double dtemp_c) {
  switch (s.outside) {
    case OutsideEffect::gain_ratio_drift: return 1.0 + s.outside_value * t_rel_h;
    case OutsideEffect::phase_drift: return std::polar(1.0, -s.outside_value * t_rel_h);
    case OutsideEffect::gain_ratio_vs_temp: return 1.0 + s.outside_value * dtemp_c;
    default: return 1.0;
  }
}

void add_outside(const Scenario& s, recording::Recording& rec, std::mt19937_64& g) {
  const auto& t = rec.column("t_s");
  const std::size_t n = rec.rows();
  const double t_mid = 0.5 * (t.front() + t.back());
  const std::vector<double>* temp = rec.has_column("temp_c") ? &rec.column("temp_c") : nullptr;
  double t_mean = 0.0;
  for (std::size_t i = 0; temp && i < n; ++i)
    t_mean += (*temp)[i] / static_cast<double>(n);
  auto& cx = rec.column("cx_v");
  auto& sx = rec.column("sx_v");
  auto& cy = rec.column("cy_v");
  auto& sy = rec.column("sy_v");
  const double angle = std::uniform_real_distribution<double>(0.0, 2.0 * kPi)(g);
  for (std::size_t i = 0; i < n; ++i) {
    if (s.outside == OutsideEffect::offset_x) {
      cx[i] += s.outside_value * std::cos(angle);
      sx[i] += s.outside_value * std::sin(angle);
      continue;
    }
    const cplx y =
        cplx(cy[i], -sy[i]) * y_gain(s, (t[i] - t_mid) / 3600.0, temp ? (*temp)[i] - t_mean : 0.0);
    cy[i] = y.real();
    sy[i] = -y.imag();
  }
}

// A reference that follows the resonance like a PLL: it pulls in from the
// metadata frequency to the wave's with a 5 s time constant and wanders
// around it by a few mHz; the envelopes are against it and the f_ref_hz
// column holds it per row.
void follow_resonance(const Scenario& s, recording::Recording& rec, std::mt19937_64& g) {
  // The column first: adding it may move the others.
  if (!rec.has_column("f_ref_hz")) rec.add_column("f_ref_hz", s.f_ref_hz);
  const auto& t = rec.column("t_s");
  const std::size_t n = rec.rows();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double wander_hz = 0.002 + 0.008 * u(g), period_s = 20.0 + 60.0 * u(g);
  const double phase0 = 2.0 * kPi * u(g);
  const double offset_hz = s.resonator.f_hz - s.f_ref_hz;
  auto& fref = rec.column("f_ref_hz");
  auto& cx = rec.column("cx_v");
  auto& sx = rec.column("sx_v");
  auto& cy = rec.column("cy_v");
  auto& sy = rec.column("sy_v");
  double phase = 0.0, f_prev = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double tr = t[i] - t.front();
    const double df = offset_hz * (1.0 - std::exp(-tr / 5.0)) +
                      wander_hz * std::sin(2.0 * kPi * tr / period_s + phase0);
    if (i > 0) phase += 2.0 * kPi * 0.5 * (df + f_prev) * (t[i] - t[i - 1]);
    f_prev = df;
    fref[i] = s.f_ref_hz + df;
    const cplx rot = std::polar(1.0, -phase);
    const cplx x = cplx(cx[i], -sx[i]) * rot, y = cplx(cy[i], -sy[i]) * rot;
    cx[i] = x.real(), sx[i] = -x.imag(), cy[i] = y.real(), sy[i] = -y.imag();
  }
}

}  // namespace

const char* outside_name(OutsideEffect e) {
  switch (e) {
    case OutsideEffect::none: return "none";
    case OutsideEffect::gain_ratio_drift: return "gain_ratio_drift";
    case OutsideEffect::phase_drift: return "phase_drift";
    case OutsideEffect::offset_x: return "offset_x";
    case OutsideEffect::gain_ratio_vs_temp: return "gain_ratio_vs_temperature";
  }
  return "?";
}

bool outside_by_name(const std::string& name, OutsideEffect& e) {
  for (int k = 1; k <= kOutsideEffectCount; ++k) {
    if (name == outside_name(static_cast<OutsideEffect>(k))) {
      e = static_cast<OutsideEffect>(k);
      return true;
    }
  }
  return false;
}

void apply_outside_effects(const Scenario& s, recording::Recording& rec) {
  if (rec.rows() == 0) return;
  std::mt19937_64 g(s.seed * 2862933555777941757ULL + 7ULL);
  // The reference first: offsets and the lock-in's 1/f noise come after the
  // mixing, in the frame of the reference the demodulator used (a pickoff
  // gain or phase commutes with it).
  if (s.pll_reference) follow_resonance(s, rec, g);
  if (s.outside != OutsideEffect::none) add_outside(s, rec, g);
  if (s.flicker_corner_hz > 0.0) add_flicker(s, rec, g);
}

}  // namespace hrg::audit::bench
