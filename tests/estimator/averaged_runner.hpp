// SPDX-License-Identifier: MIT
#pragma once

// Free-decay windows taken from the averaged resonator model (sim_target),
// with white noise on the four demodulated quadratures at the 1 kHz control
// rate, turned into wave variables as the firmware does (dsp).

#include <cmath>
#include <random>

#include <estimator/estimator.hpp>
#include <estimator/types.hpp>

#include <dsp/wave_variables.hpp>
#include <sim_target/averaged_model.hpp>

namespace hrg::est::test {

// Realistic pickoff noise: 1 uV/rtHz referred to the pickoff, over the
// 500 Hz band of the 1 kHz demodulated output -> 2.2e-5 V per quadrature
// sample, i.e. 2.2e-5 relative to the 1 V working amplitude (93 dB).
inline constexpr double kNoiseDensityVPerRtHz = 1e-6;
inline constexpr double kQuadratureNoiseV = kNoiseDensityVPerRtHz * 22.360679774997898;

inline ParamVector truth_of(const sim::ResonatorParams& r) {
  const double nu = r.nu_per_s();
  const double dw = r.half_split_rad_s();
  ParamVector p;
  p << nu, nu * r.dmu * std::cos(4 * r.th_mu_rad), nu * r.dmu * std::sin(4 * r.th_mu_rad),
      dw * std::cos(4 * r.th_w_rad), dw * std::sin(4 * r.th_w_rad);
  return p;
}

template <typename Rng>
WaveSample measure(const sim::AveragedModel& m, double noise_v, Rng& rng) {
  const sim::Demodulated d = m.demodulated();
  dsp::Quadratures<double> q{d.cx_v, d.sx_v, d.cy_v, d.sy_v};
  if (noise_v > 0) {
    std::normal_distribution<double> n(0.0, noise_v);
    q.cx += n(rng);
    q.sx += n(rng);
    q.cy += n(rng);
    q.sy += n(rng);
  }
  const auto w = dsp::wave_variables<double>(q);
  return WaveSample{m.time_s(), w.a_A_v, w.a_B_v, w.theta_A_rad, w.E_v2};
}

// One free-decay window: excitation off at the model's present time, samples
// every dt_s for duration_s, fed to `sink(sample)`.
template <typename Rng, typename Sink>
void free_decay_window(sim::AveragedModel& m, double duration_s, double noise_v, Rng& rng,
                       Sink&& sink, double dt_s = 1e-3) {
  sim::EnvelopeDrive off;
  off.excitation = false;
  m.set_drive(off);
  const int n = static_cast<int>(std::lround(duration_s / dt_s));
  for (int i = 0; i < n; ++i) {
    m.advance(dt_s);
    sink(measure(m, noise_v, rng));
  }
}

}  // namespace hrg::est::test
