// SPDX-License-Identifier: MIT
#include "campaign.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim_target/averaged_model.hpp"
#include "sim_target/profile.hpp"

namespace hrg::audit::bench {

namespace {

constexpr double kPi = std::numbers::pi;
const sim::cplx kI(0.0, 1.0);

double uniform(std::mt19937_64& g, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(g);
}

struct Segment {
  bool excitation;
  double duration_s;
  double rate_dps;
  bool move_pattern;
  double target_rad;
};

std::vector<Segment> plan(const Scenario& s, std::mt19937_64& g) {
  std::vector<Segment> out;
  double t = 0.0;
  bool long_done = false;
  double rate = 0.0;
  while (t < s.duration_s) {
    if (s.design == Design::ringdown) {
      rate =
          uniform(g, 0, 1) < 0.4 ? 0.0 : uniform(g, 3.0, 20.0) * (uniform(g, 0, 1) < 0.5 ? -1 : 1);
      out.push_back({true, 4.0, rate, true, uniform(g, -kPi / 6, kPi / 6)});
      double free_s = uniform(g, 10.0, 30.0);
      if (!long_done && t > 0.3 * s.duration_s) {
        free_s = std::min(200.0, 0.3 * s.duration_s);
        rate = 0.0;
        long_done = true;
      }
      out.push_back({false, free_s, rate, false, 0.0});
      t += 4.0 + free_s;
    } else {
      if (out.empty() || uniform(g, 0, 1) < 0.25) {
        rate = uniform(g, -30.0, 30.0);
      }
      const double on_s = uniform(g, 4.0, 10.0);
      const double off_s = uniform(g, 0.4, 2.0);
      out.push_back({true, on_s, rate, false, 0.0});
      out.push_back({false, off_s, rate, false, 0.0});
      t += on_s + off_s;
    }
  }
  return out;
}

// What the firmware's default chain and loops are built for: a resonance
// within its PLL's pull-in of the 5 kHz centre, a pump threshold well inside
// the 10 V DAC, an amplitude inside the 2.5 V ADC; the table's turn at
// 6-15 deg/s and windows of 0.3-1 s. The campaign lasts as long as the turn.
void restrict_to_firmware(Scenario& s, std::mt19937_64& g) {
  auto& r = s.resonator;
  r.f_hz = 5000.0 + uniform(g, -1.0, 1.0);
  r.q = std::exp(uniform(g, std::log(2e6), std::log(8e6)));
  s.amplitude_v = uniform(g, 0.6, 1.4);
  s.noise_v = s.amplitude_v * std::exp(uniform(g, std::log(1e-5), std::log(6e-5)));
  const double v_th = uniform(g, 2.5, 5.0);
  s.electrodes.pump_gain_per_s2_v2 = 8.0 * r.omega_rad_s() * r.nu_per_s() / (v_th * v_th);
  s.window_s = uniform(g, 0.3, 1.0);
  s.sweep_rate_dps = uniform(g, 6.0, 15.0) * (uniform(g, 0, 1) < 0.5 ? -1 : 1);
  s.temp_phase_rad = uniform(g, 0.0, 2.0 * kPi);
  s.duration_s = firmware_duration_s(s);
}

}  // namespace

sim::Profile temperature_profile(const Scenario& s, double phase_rad) {
  if (!s.temp_cycles) {
    return sim::Profile::sine(s.temp_swing_c, 1.0 / (1.3 * s.duration_s), phase_rad)
        .add_offset(s.temp_mean_c);
  }
  // h(u) = sin(4 pi u + phase) minus its least-squares line over u in [0, 1]:
  // the line's slope is 12 int (u - 1/2) h du, its offset the mean of h (0
  // over two whole cycles).
  const double slope = -12.0 * std::cos(phase_rad) / (4.0 * kPi);
  constexpr int kPoints = 256;
  std::vector<sim::ProfilePoint> pts;
  std::vector<double> h(kPoints + 1);
  double peak = 0.0;
  for (int i = 0; i <= kPoints; ++i) {
    const double u = static_cast<double>(i) / kPoints;
    h[static_cast<std::size_t>(i)] = std::sin(4.0 * kPi * u + phase_rad) - slope * (u - 0.5);
    peak = std::max(peak, std::abs(h[static_cast<std::size_t>(i)]));
  }
  for (int i = 0; i <= kPoints; ++i) {
    pts.push_back({s.duration_s * static_cast<double>(i) / kPoints,
                   s.temp_mean_c + s.temp_swing_c * h[static_cast<std::size_t>(i)] / peak});
  }
  return sim::Profile::ramps(std::move(pts));
}

Scenario random_scenario(Design design, double duration_s, uint64_t seed) {
  std::mt19937_64 g(seed * 7919ULL + 17ULL);
  Scenario s;
  s.design = design;
  s.seed = seed;
  s.duration_s = duration_s;
  auto& r = s.resonator;
  r.f_hz = uniform(g, 4800.0, 5200.0);
  r.q = std::exp(uniform(g, std::log(1.5e6), std::log(8e6)));
  r.dmu = uniform(g, 0.003, 0.06) * (uniform(g, 0, 1) < 0.5 ? -1 : 1);
  r.th_mu_rad = uniform(g, 0.0, kPi / 2);
  r.split_hz = uniform(g, 1e-4, 1.2e-3);
  r.th_w_rad = uniform(g, 0.0, kPi / 2);
  r.angular_gain = 0.554;
  s.temp_mean_c = uniform(g, 15.0, 40.0);
  s.temp_swing_c = uniform(g, 0.5, 3.0);
  r.temp_ref_c = s.temp_mean_c + uniform(g, -0.5, 0.5);
  s.f_ref_hz = r.f_hz + uniform(g, -0.5, 0.5);
  s.amplitude_v = uniform(g, 0.3, 1.6);
  s.noise_v = s.amplitude_v * std::exp(uniform(g, std::log(1e-5), std::log(8e-5)));
  // Pump gain giving a parametric threshold of 6-12 V at this damping.
  const double v_th = uniform(g, 6.0, 12.0);
  s.electrodes.pump_gain_per_s2_v2 = 8.0 * r.omega_rad_s() * r.nu_per_s() / (v_th * v_th);
  if (design == Design::firmware) restrict_to_firmware(s, g);
  return s;
}

namespace {

recording::Recording simulate_averaged(const Scenario& s);

}  // namespace

recording::Recording simulate(const Scenario& s) {
  recording::Recording rec =
      s.design == Design::firmware ? simulate_firmware(s) : simulate_averaged(s);
  apply_outside_effects(s, rec);
  return rec;
}

namespace {

recording::Recording simulate_averaged(const Scenario& s) {
  std::mt19937_64 g(s.seed * 104729ULL + 3ULL);
  std::normal_distribution<double> noise(0.0, s.noise_v);
  const auto segs = plan(s, g);
  sim::AveragedModel m(s.resonator, s.electrodes, s.effects, s.f_ref_hz);
  // The temperature over the campaign, with a random phase.
  m.set_temperature_profile(temperature_profile(s, uniform(g, 0.0, 2.0 * kPi)));
  // Rate steps exactly at the sample where their segment starts.
  const double dt = 1.0 / s.sample_rate_hz;
  std::vector<sim::ProfilePoint> rate_points;
  long long k0 = 0;
  for (const auto& seg : segs) {
    rate_points.push_back({static_cast<double>(k0) * dt - 0.5 * dt,
                           seg.rate_dps * kPi / 180.0 + sim::kEarthRateRadS * 0.6});
    k0 += std::llround(seg.duration_s / dt);
  }
  m.set_rate_profile(sim::Profile::steps(rate_points));
  m.set_standing_wave(s.amplitude_v, uniform(g, -kPi / 4, kPi / 4), 0.0, 0.0);
  recording::Recording rec(
      {"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc", "pump_v", "temp_c", "rate_dps"}, s.f_ref_hz,
      s.resonator.angular_gain);
  rec.set_metadata("source", s.design == Design::ringdown ? "audit benchmark ring-down campaign"
                                                          : "audit benchmark telemetry");
  const double w = s.resonator.omega_rad_s();
  const double nu = s.resonator.nu_per_s();
  const double kpump = s.electrodes.pump_gain_per_s2_v2;
  const double gf = s.electrodes.forcer_gain_per_s2;
  const double sensor_temp_noise = 0.003;
  std::normal_distribution<double> tnoise(0.0, sensor_temp_noise);
  double time = 0.0;
  double target = 0.0;
  std::size_t k = 0;
  for (const auto& seg : segs) {
    const auto n = static_cast<std::size_t>(std::llround(seg.duration_s / dt));
    for (std::size_t i = 0; i < n; ++i, ++k) {
      sim::EnvelopeDrive drive;
      if (seg.excitation) {
        const auto wv = m.wave();
        const double a = std::max(wv.a_A_v, 1e-6);
        // Amplitude: parametric pump at the best phase, growth rate set by a
        // proportional loop around the damping.
        const double growth = std::max(0.0, nu + 2.0 * (s.amplitude_v - a) / s.amplitude_v);
        drive.excitation = true;
        drive.pump_v = std::min(std::sqrt(8.0 * w * growth / kpump), 40.0);
        drive.pump_phase_rad = kPi / 4.0;
        drive.pump_follows_wave = true;
        // Forcers in the wave's frame: null the quadrature, move the pattern.
        const double c2 = std::cos(2.0 * wv.theta_rad), s2 = std::sin(2.0 * wv.theta_rad);
        double theta_rate = 0.0;
        if (seg.move_pattern) {
          // Target relative to where the segment started (a move of up to 30 deg).
          if (i == 0) target = wv.theta_rad + seg.target_rad;
          const double err = std::remainder(target - wv.theta_rad, kPi / 2.0);
          theta_rate = std::clamp(6.0 * err, -0.5, 0.5);
        }
        const sim::cplx u_perp = 2.0 * a * theta_rate + kI * 5.0 * wv.a_B_v;
        drive.forcer_x_v = kI * 2.0 * w * (u_perp * (-s2)) / gf;
        drive.forcer_y_v = kI * 2.0 * w * (u_perp * c2) / gf;
        drive.forcers_follow_wave = true;
      }
      m.set_drive(drive);
      const auto row = m.row(s.f_ref_hz);
      time = m.time_s();
      rec.append_row({time, row.d.cx_v + noise(g), row.d.sx_v + noise(g), row.d.cy_v + noise(g),
                      row.d.sy_v + noise(g), static_cast<double>(row.exc), row.pump_v,
                      row.temp_c + tnoise(g), row.rate_dps});
      m.advance(dt);
    }
  }
  rec.find_gaps();
  return rec;
}

}  // namespace

}  // namespace hrg::audit::bench
