// SPDX-License-Identifier: MIT
#include "firmware/can/telemetry.hpp"

namespace hrg::fw::can {

namespace {

double b(bool v) { return v ? 1.0 : 0.0; }
double sat_u(uint32_t v, uint32_t max) { return static_cast<double>(v > max ? max : v); }

void put(const MessageDef& m, std::size_t index, double value, hal::CanFrame& f) {
  encode_signal(m.signals[index], value, f);
}

}  // namespace

TelemetryConfig TelemetryConfig::defaults() {
  TelemetryConfig c;
  for (std::size_t i = 0; i < kTelemetryCount; ++i)
    c.rate_hz[i] = kTelemetry[i].default_rate_hz;
  return c;
}

bool TelemetryConfig::valid(uint32_t base_rate_hz) const {
  // A recording row is one HRG_WAVE_X and the HRG_WAVE_Y of the same sample.
  const uint16_t wave = rate_hz[static_cast<std::size_t>(Tm::wave_x)];
  if (rate_hz[static_cast<std::size_t>(Tm::wave_y)] != wave ||
      rate_hz[static_cast<std::size_t>(Tm::row)] != wave) {
    return false;
  }
  for (const auto r : rate_hz) {
    if (r == 0) continue;
    if (r > base_rate_hz || base_rate_hz % r != 0) return false;
  }
  return true;
}

double bus_load_fraction(const TelemetryConfig& config, uint32_t bitrate_bps) {
  double bits_per_s = 0;
  for (std::size_t i = 0; i < kTelemetryCount; ++i) {
    bits_per_s += static_cast<double>(config.rate_hz[i]) *
                  static_cast<double>(worst_case_frame_bits(kTelemetry[i].dlc));
  }
  return bits_per_s / static_cast<double>(bitrate_bps);
}

void encode_telemetry(Tm message, const TelemetrySnapshot& s, uint8_t seq, hal::CanFrame& f) {
  const MessageDef& m = telemetry_def(message);
  f = hal::CanFrame{};
  f.id = m.id;
  f.len = m.dlc;
  switch (message) {
    case Tm::wave_x:
      put(m, sig::cx_v, s.cx_v, f);
      put(m, sig::sx_v, s.sx_v, f);
      put(m, sig::exc, b(s.exc_on), f);
      break;
    case Tm::wave_y:
      put(m, sig::cy_v, s.cy_v, f);
      put(m, sig::sy_v, s.sy_v, f);
      break;
    case Tm::angle:
      put(m, sig::theta_a_rad, s.theta_a_rad, f);
      put(m, sig::output_angle_rad, s.output_angle_rad, f);
      break;
    case Tm::loops:
      put(m, sig::pll_freq_hz, s.pll_freq_hz, f);
      put(m, sig::quad_effort, s.quad_effort, f);
      put(m, sig::pll_locked, b(s.pll_locked), f);
      break;
    case Tm::pump:
      put(m, sig::pump_v, s.pump_v, f);
      put(m, sig::pump_phase_rad, s.pump_phase_rad, f);
      put(m, sig::agc_setpoint_v, s.agc_setpoint_v, f);
      break;
    case Tm::status:
      put(m, sig::mode, static_cast<double>(static_cast<uint8_t>(s.mode)), f);
      put(m, sig::exc_on, b(s.exc_on), f);
      put(m, sig::exc_line, b(s.exc_line), f);
      put(m, sig::fault_input, b(s.fault_input), f);
      put(m, sig::ident_active, b(s.ident_active), f);
      put(m, sig::comp_valid, b(s.comp_valid), f);
      put(m, sig::cal_withdrawn, b(s.cal_withdrawn), f);
      put(m, sig::cal_damping_refuted, b(s.cal_damping_refuted), f);
      put(m, sig::cal_gap_refuted, b(s.cal_gap_refuted), f);
      put(m, sig::faults, s.faults, f);
      put(m, sig::temp_c, s.temp_c, f);
      put(m, sig::comp_reasons, s.comp_reasons, f);
      break;
    case Tm::est_damping:
      put(m, sig::nu_per_s, s.nu_per_s, f);
      put(m, sig::dnu_c_per_s, s.dnu_c_per_s, f);
      put(m, sig::dnu_s_per_s, s.dnu_s_per_s, f);
      break;
    case Tm::est_split:
      put(m, sig::dw_c_rad_s, s.dw_c_rad_s, f);
      put(m, sig::dw_s_rad_s, s.dw_s_rad_s, f);
      break;
    case Tm::est_quality:
      put(m, sig::cond_log10, s.cond_log10, f);
      put(m, sig::coverage, s.coverage, f);
      put(m, sig::windows, sat_u(s.windows, 65535), f);
      put(m, sig::est_valid, b(s.est_valid), f);
      put(m, sig::readout_damping_sigmas, s.readout_damping_sigmas, f);
      break;
    case Tm::exec:
      put(m, sig::overruns, sat_u(s.overruns, 65535), f);
      put(m, sig::missed_ticks, sat_u(s.missed_ticks, 65535), f);
      put(m, sig::max_frame_us, sat_u(s.max_frame_us, 65535), f);
      put(m, sig::cpu_load_pct, s.cpu_load_pct, f);
      break;
    case Tm::info:
      put(m, sig::protocol_version, kProtocolVersion, f);
      put(m, sig::angular_gain, s.angular_gain, f);
      put(m, sig::window_period_s, s.window_period_s, f);
      put(m, sig::window_length_s, s.window_length_s, f);
      break;
    case Tm::can_stats:
      put(m, sig::tx_queue_full, sat_u(s.can.tx_queue_full, 65535), f);
      put(m, sig::error_frames, sat_u(s.can.error_frames, 65535), f);
      put(m, sig::bus_off_events, sat_u(s.can.bus_off_events, 255), f);
      put(m, sig::restarts, sat_u(s.can.restarts, 255), f);
      put(m, sig::can_state, static_cast<double>(static_cast<uint8_t>(s.can_state)), f);
      break;
    case Tm::row:
      put(m, sig::row_t_s, s.row_t_s, f);
      put(m, sig::row_pump_v, s.row_pump_v, f);
      put(m, sig::row_exc, b(s.row_exc), f);
      break;
    case Tm::reference: put(m, sig::f_ref_hz, s.f_ref_hz, f); break;
    case Tm::cal_readings: encode_cal_readings(s.estimates, 0, seq, f); return;
  }
  // Every telemetry message ends its table with `seq`.
  const SignalDef* seq_sig = find_signal(m, "seq");
  if (seq_sig != nullptr) put_bits(f, seq_sig->start_bit, seq_sig->length, seq);
}

void encode_cal_readings(const FirmwareEstimates& e, uint8_t page, uint8_t seq, hal::CanFrame& f) {
  const MessageDef& m = telemetry_def(Tm::cal_readings);
  f = hal::CanFrame{};
  f.id = m.id;
  f.len = m.dlc;
  put(m, sig::readings_page, page, f);
  put(m, sig::thermal_valid, b(e.thermal_damping), f);
  put(m, sig::self_cal_valid, b(e.pickoff), f);
  put_bits(f, m.signals[sig::readings_seq].start_bit, kSeqBits, seq);
  // Without an edge the feedthrough signals stay zero (0 edges says so).
  const FirmwareEstimates none{};
  const FirmwareEstimates& ft = e.feedthrough ? e : none;
  // Without a pickoff map its signals stay zero (self_cal_valid says so).
  const FirmwareEstimates& map = e.pickoff ? e : none;
  const auto pair = [&](std::size_t a, double va, std::size_t b2, double vb) {
    put(m, a, va, f);
    put(m, b2, vb, f);
  };
  switch (page) {
    case 0:
      pair(sig::pump_edge_edges, sat_u(ft.edges, 65535), sig::pump_edge_in_force_s, ft.in_force_s);
      break;
    case 1:
      pair(sig::pump_edge_x_re, ft.feedthrough_residual_v_per_v.x_re, sig::pump_edge_x_im,
           ft.feedthrough_residual_v_per_v.x_im);
      break;
    case 2:
      pair(sig::pump_edge_y_re, ft.feedthrough_residual_v_per_v.y_re, sig::pump_edge_y_im,
           ft.feedthrough_residual_v_per_v.y_im);
      break;
    case 3:
      pair(sig::pump_edge_sigma, ft.feedthrough_sigma_v_per_v, sig::pump_edge_scatter,
           ft.feedthrough_scatter_v_per_v);
      break;
    case 4:
      pair(sig::pump_edge_in_force_x_re, ft.feedthrough_in_force_v_per_v.x_re,
           sig::pump_edge_in_force_x_im, ft.feedthrough_in_force_v_per_v.x_im);
      break;
    case 5:
      pair(sig::pump_edge_in_force_y_re, ft.feedthrough_in_force_v_per_v.y_re,
           sig::pump_edge_in_force_y_im, ft.feedthrough_in_force_v_per_v.y_im);
      break;
    case 6:
      pair(sig::thermal_damping_per_c, e.thermal_damping ? e.thermal_damping_per_c : 0.0,
           sig::thermal_damping_sigma_per_c,
           e.thermal_damping ? e.thermal_damping_sigma_per_c : 0.0);
      break;
    case 7:
      pair(sig::self_cal_gain, map.pickoff_gain, sig::self_cal_gain_sigma, map.pickoff_gain_sigma);
      break;
    case 8:
      pair(sig::self_cal_misalignment, map.pickoff_misalignment_rad,
           sig::self_cal_misalignment_sigma, map.pickoff_misalignment_sigma_rad);
      break;
    default:
      pair(sig::self_cal_phase, map.pickoff_phase_rad, sig::self_cal_phase_sigma,
           map.pickoff_phase_sigma_rad);
      break;
  }
}

hal::CanFrame encode_lab_table(double rate_dps, double temp_c, uint8_t seq) {
  hal::CanFrame f;
  f.id = kLabTable.id;
  f.len = kLabTable.dlc;
  put(kLabTable, sig::table_rate_dps, rate_dps, f);
  put(kLabTable, sig::table_temp_c, temp_c, f);
  put_bits(f, kLabTable.signals[sig::table_seq].start_bit, kSeqBits, seq);
  return f;
}

TelemetryEncoder::TelemetryEncoder(const TelemetryConfig& config, uint32_t base_rate_hz)
    : config_(config), base_rate_hz_(base_rate_hz), config_ok_(config.valid(base_rate_hz)) {
  if (!config_ok_) config_ = TelemetryConfig::defaults();
}

namespace {

// HRG_WAVE_Y and HRG_ROW go out in the same frame as HRG_WAVE_X (same row,
// same seq).
bool row_part(std::size_t i) {
  return i == static_cast<std::size_t>(Tm::wave_x) || i == static_cast<std::size_t>(Tm::wave_y) ||
         i == static_cast<std::size_t>(Tm::row);
}

}  // namespace

bool TelemetryEncoder::due(std::size_t i, uint64_t frame) const {
  const uint16_t rate = config_.rate_hz[i];
  if (rate == 0) return false;
  // An invalid base rate leaves rates above it: send those every frame.
  const uint64_t period = rate >= base_rate_hz_ ? 1 : base_rate_hz_ / rate;
  const std::size_t phase = row_part(i) ? 0 : i;
  return (frame + phase) % period == 0;
}

bool TelemetryEncoder::cal_readings_due() const {
  return page_ == 0 && due(static_cast<std::size_t>(Tm::cal_readings), frame_);
}

std::size_t TelemetryEncoder::tick(const TelemetrySnapshot& s, std::span<hal::CanFrame> out) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < kTelemetryCount && n < out.size(); ++i) {
    if (row_part(i) && !s.row_ready) continue;
    if (!due(i, frame_)) continue;
    encode_now(static_cast<Tm>(i), s, out[n++]);
  }
  ++frame_;
  return n;
}

void TelemetryEncoder::encode_now(Tm message, const TelemetrySnapshot& s, hal::CanFrame& out) {
  const auto i = static_cast<std::size_t>(message);
  if (message == Tm::cal_readings) {
    // A set's pages all come from the readings held at its first page.
    if (page_ == 0) held_ = s.estimates;
    encode_cal_readings(held_, page_, seq_[i], out);
    page_ = static_cast<uint8_t>((page_ + 1u) % kCalReadingsPages);
  } else {
    encode_telemetry(message, s, seq_[i], out);
  }
  seq_[i] = static_cast<uint8_t>(seq_[i] + 1u);
}

}  // namespace hrg::fw::can
