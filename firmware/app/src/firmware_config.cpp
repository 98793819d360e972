// SPDX-License-Identifier: MIT
#include "firmware/app/firmware_config.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "dsp/demodulator.hpp"

namespace hrg::fw::app {

void apply_window_plan(WindowConfig& w, WindowPlan plan) {
  if (plan == WindowPlan::long_run) {
    // 4 windows of 5 s per 4 theta bin while the table turns (64 windows,
    // 320 s: 8.9 % of an hour), 10 s apart so the AGC is back at the set
    // point between them; each carries 125 times the decay information of a
    // 1 s window. The campaign ends only when every bin has its 4.
    w.length_frames = 5000;
    w.period_frames = 10000;
    w.max_wait_frames = 20000;
    w.windows_per_bin = 4;
    w.min_windows_per_bin = 4;
    // In operation a check window at least every 10 min (0.8 %), and
    // continued identification up to 2 % excitation off over the run.
    w.check_period_frames = 600000;
    w.first_check_delay_frames = kFirstCheckDelayFrames;
    // ... and one as soon as the base is still for a window period (where a
    // fit made while turning is most likely wrong), the rate averaged over
    // 0.2 s for it: over the output's 10 ms its noise on a still table
    // (1.4e-3 rad/s rms on the 4.2 kHz resonator) is above the 1e-3 limit.
    w.still_rate_average_frames = 200;
    w.operation_duty = kDefaultOperationDuty;
    // Continued identification in 30 s windows (216 times a 5 s window's
    // decay information; 9 % of the amplitude at Q 5e6, 5 kHz; derive()
    // shortens them for a faster decay), checks between them in the
    // campaign's 5 s (forced every period, they would take 5 % at 30 s).
    // Steady default day (bench_sim_day): model ADB 0.0035 deg/h against a
    // bound of 0.0160 at 24 h, 1.98 % off (5 s windows: 0.0311 / 0.0216).
    w.operation_length_frames = 30000;
    w.check_length_frames = w.length_frames;
    return;
  }
  // Long windows: the decay-rate information of one window grows as T^3
  // (slope of a noisy line), so one 1 s window is worth about 20 windows of
  // 130 ms for a quarter of the excitation-off time.
  w.length_frames = 1000;
  w.period_frames = 2000;
  w.max_wait_frames = 10000;
  w.windows_per_bin = 4;
  w.min_windows_per_bin = 2;
  // A few-minute run: a check window every 20 s after the campaign (they
  // also feed the identification); the duty rule never opens more.
  w.check_period_frames = 20000;
  w.first_check_delay_frames = kFirstCheckDelayFrames;
  w.operation_duty = kDefaultOperationDuty;
}

void limit_operation_windows(WindowConfig& w, const dsp::ChainConfig& chain) {
  // Amplitude decay time 1/nu = Q / (pi f): a window of a tenth of it loses
  // 10 % of the amplitude for the AGC to recover.
  if (w.operation_length_frames == 0 || !(chain.q_factor > 0.0) || !(chain.f_center_hz > 0.0))
    return;
  const double decay_s = chain.q_factor / (std::numbers::pi * chain.f_center_hz);
  const double limit_frames = std::max(static_cast<double>(w.length_frames),
                                       kOperationWindowDecayShare * decay_s * kBaseRateHz);
  if (static_cast<double>(w.operation_length_frames) > limit_frames)
    w.operation_length_frames = static_cast<uint32_t>(limit_frames);
}

FirmwareConfig default_firmware_config(const ConverterLayout& conv, WindowPlan plan) {
  FirmwareConfig f;
  GyroConfig& g = f.gyro;
  g.amplitude_set_v = 1.0;
  WindowConfig& w = g.windows;
  w.bins = 16;
  w.condition_good = 50.0;
  w.coverage_good = 1.0;
  apply_window_plan(w, plan);
  // The pump's gap part of D_Phi is used only once the pattern angles seen
  // with the excitation on make its 3x3 fit well conditioned: an early fit
  // from a few nearby angles adds more than it removes (default run: ADB
  // 2.5 deg/h at the estimator's default 1e3, 0.15 deg/h at 10).
  f.estimator.pump.max_kappa_2 = 10.0;
  // ... and only when its fitted gap harmonic is above the ideal electrode's
  // noise (PumpDriftEstimator::Config::min_gap).
  f.estimator.pump.min_gap = 2.0e-3;
  derive(f, conv);
  return f;
}

void derive(FirmwareConfig& cfg, const ConverterLayout& conv) {
  cfg.chain = chain_config_for(conv, cfg.chain);
  limit_operation_windows(cfg.gyro.windows, cfg.chain);
  cfg.chain.amplitude_setpoint_v = cfg.gyro.amplitude_set_v;
  cfg.gyro.monitor.amplitude_set_v = cfg.gyro.amplitude_set_v;
  cfg.gyro.envelope = envelope_reference_config(cfg.chain, conv);
  cfg.gyro.pump_edge.drive_free_rows = drive_free_blocks(cfg.chain, conv.dac_latency_samples);
  cfg.gyro.pump_edge.edge_offset_rows = pump_edge_offset_rows(cfg.chain);
  cfg.estimator.pump.pump_lag_samples = pump_lag_samples(cfg.chain);
  const double l = static_cast<double>(cfg.chain.block_frames);
  cfg.gyro.pump_edge.row_centre_blocks = (1.0 + 0.5 * dsp::kDecimatorOrder * (l - 1.0)) / l;
  cfg.gyro.pump_edge.row_noise_correlation =
      dsp::decimator_row_noise_correlation(cfg.chain.block_frames);
}

can::EnvelopeReferenceConfig envelope_reference_config(const dsp::ChainConfig& chain,
                                                       const ConverterLayout& conv) {
  can::EnvelopeReferenceConfig e;
  e.f_ref_hz = chain.f_center_hz;
  const double l = static_cast<double>(chain.block_frames);
  e.block_period_s = l / chain.sample_rate_hz;
  e.centre_blocks = dsp::kDecimatorOrder / 2;
  // The DAC's pipeline is counted once more on top of the chain's lead (which
  // holds it already): a row is called drive-free one block late rather
  // than early.
  e.drive_free_blocks = drive_free_blocks(chain, conv.dac_latency_samples);
  return e;
}

uint32_t drive_free_blocks(const dsp::ChainConfig& chain, double dac_latency_samples) {
  const double l = static_cast<double>(chain.block_frames);
  return static_cast<uint32_t>(1.0 + std::ceil((chain.dac_lead_frames + dac_latency_samples +
                                                (dsp::kDecimatorOrder - 1.0) * (l - 1.0)) /
                                               l));
}

double pump_edge_offset_rows(const dsp::ChainConfig& chain) {
  const double l = static_cast<double>(chain.block_frames);
  return (chain.dac_lead_frames + 0.5 + 0.5 * dsp::kDecimatorOrder * (l - 1.0)) / l;
}

int pump_lag_samples(const dsp::ChainConfig& chain) {
  // The estimator holds kMaxPumpLag pumps (7 blocks of DAC lead and demodulator
  // delay); a chain slower than that is fitted at that lag.
  const long lag = std::lround(pump_edge_offset_rows(chain) - 0.5);
  return static_cast<int>(std::clamp<long>(lag, 0, est::PumpDriftEstimator::kMaxPumpLag));
}

}  // namespace hrg::fw::app
