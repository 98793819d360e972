// SPDX-License-Identifier: MIT
// The main job's scenarios: the simulated target, the rate-table schedule and
// the firmware's configuration derived from them.
#include <cmath>
#include <numbers>

#include "sim_run/run.hpp"
#include "sim_run/table_schedule.hpp"

namespace hrg::sim_run {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Runs at least this long get an identification phase of their own, until
// kLongIdentS of simulated time.
constexpr double kLongRunS = 1800.0;
constexpr double kLongIdentS = 800.0;

// The seed's example resonator behind a 24-bit 100 kHz ADC, as
// sim_target/scenarios/default.toml.
sim::SimConfig seed_target() {
  sim::SimConfig s;
  s.resonator = sim::ResonatorParams{};  // the seed's example resonator
  // Axes away from the pickoffs so that all four anisotropy terms are non-zero.
  s.resonator.th_mu_rad = 15.0 * kDeg;
  s.resonator.th_w_rad = 40.0 * kDeg;
  // 1 uV/sqrt(Hz) pickoff noise over the 50 kHz band, two samples of DAC
  // pipeline, a resonator at rest (a residual 1 mV ring).
  s.adc.noise_v_rms = {2.2e-4, 2.2e-4};
  s.dac.latency_samples = 2;
  s.initial.amplitude_v = 0.001;
  s.seed = 20240531;
  return s;
}

// Ring-up, then the identification sweep: two full 4 theta turns of the
// pattern. Runs of an hour or more turn back and forth until kLongIdentS
// with long windows (see fw::app::WindowPlan) before the parks, so that the
// model applied during the bias test has converged (the decay-rate
// information of a window grows as T^3).
void identification_sweep(TableSchedule& sch, double k, bool long_run) {
  const double sweep_rate = 10.0 * kDeg;  // case rate, pattern at about 2.8 deg/s
  const double sweep_case_rad = sim_run::sweep_case_rad(k);
  sch.hold(kRingUpS);
  sch.turn(sweep_case_rad, sweep_rate, 1.0);
  if (long_run) {
    double sign = -1.0;
    while (sch.t < kLongIdentS) {
      sch.turn(sign * sweep_case_rad, sweep_rate, 1.0);
      sign = -sign;
    }
  }
  sch.hold(2.0);
}

// Bias test: steps of 90/n deg of pattern angle (a 4 theta turn over n
// parks), each followed by a settle time and a still hold. A longer duration
// lengthens the holds; a shorter one drops the parks that do not fit. After
// the parks the table stays still for a while: the longest still record, for
// the Allan deviation (dropped first when the run is shortened).
void parked_angles(TableSchedule& sch, RunConfig& j, double k, double duration_s, int bias_angles) {
  const double settle_s = 2.0;
  const double base_hold_s = 6.0;
  const double step_case_rad = (std::numbers::pi / 2.0) / bias_angles * 2.0 / k;
  const double slew_rate = 20.0 * kDeg;
  const double step_s = std::fabs(step_case_rad) / slew_rate + 0.5;
  const double final_hold_s = 100.0;
  double hold_s = base_hold_s;
  const double t_bias0 = sch.t;
  const double parks_s = bias_angles * (step_s + settle_s + base_hold_s);
  if (duration_s > t_bias0 + parks_s + final_hold_s) {
    hold_s = (duration_s - final_hold_s - t_bias0) / bias_angles - step_s - settle_s;
  }
  for (int i = 0; i < bias_angles; ++i) {
    if (duration_s > 0 && sch.t + step_s + settle_s + hold_s > duration_s) break;
    sch.turn(-step_case_rad, slew_rate, 0.5);
    sch.hold(settle_s);
    const double t0 = sch.t;
    sch.hold(hold_s);
    j.parks.push_back({t0, sch.t});
  }
  if (duration_s <= 0) sch.hold(final_hold_s);
}

}  // namespace

RunConfig default_run(double duration_s, int bias_angles) {
  RunConfig j;
  j.description =
      "seed resonator (5 kHz, Q 5e6, dQ/Q 0.1, split 5e-4 Hz); Earth rate at 55.75 deg N; "
      "ring-up from rest, rate-table sweep, IEEE 1431 style parked-angle bias test";
  j.sim = seed_target();
  j.earth_rate_rad_s = sim::kEarthRateRadS * std::sin(j.latitude_deg * kDeg);
  const double k = j.sim.resonator.angular_gain;
  const bool long_run = duration_s >= kLongRunS;
  TableSchedule sch;
  identification_sweep(sch, k, long_run);
  j.sweep_end_s = sch.t;
  parked_angles(sch, j, k, duration_s, bias_angles);
  j.duration_s = duration_s > 0 ? duration_s : sch.t;
  j.sim.rate_rad_s = sch.profile(j.earth_rate_rad_s);

  // The firmware's defaults, K from the resonator's calibration. The rate
  // table turns the pattern here; commanded rotation is for a base that
  // never turns (the output is held while the pattern is moved).
  j.firmware = fw::app::default_firmware_config(
      converter_layout(j.sim),
      long_run ? fw::app::WindowPlan::long_run : fw::app::WindowPlan::standard);
  j.firmware.gyro.angular_gain = k;
  j.firmware.gyro.windows.rotate_on_static_base = false;
  derive_firmware_config(j);
  return j;
}

RunConfig static_base_run(double duration_s) {
  RunConfig j = default_run(60.0, 4);
  j.description =
      "seed resonator on a static base (Earth rate at 55.75 deg N only); the firmware turns "
      "the pattern on purpose to fill the 4 theta bins";
  j.sim.rate_rad_s = sim::Profile::constant(j.earth_rate_rad_s);
  j.parks.clear();
  j.duration_s = duration_s > 0 ? duration_s : 300.0;
  j.sweep_end_s = j.duration_s;
  fw::WindowConfig& w = j.firmware.gyro.windows;
  w.rotate_on_static_base = true;
  w.min_windows_per_bin = 1;
  w.windows_per_bin = 2;
  w.period_frames = 1500;
  derive_firmware_config(j);
  return j;
}

fw::ConverterLayout converter_layout(const sim::SimConfig& sim) {
  // ADC full scale 2.5 V on the simulated board, 2.0 V in the chain's defaults.
  fw::ConverterLayout conv;
  conv.sample_rate_hz = sim.adc.sample_rate_hz;
  conv.block_frames = sim.adc.block_frames;
  conv.adc_full_scale_v = sim.adc.full_scale_v;
  conv.dac_full_scale_v = sim.dac.full_scale_v;
  conv.dac_latency_samples = sim.dac.latency_samples;
  return conv;
}

void derive_firmware_config(RunConfig& j) { fw::app::derive(j.firmware, converter_layout(j.sim)); }

}  // namespace hrg::sim_run
