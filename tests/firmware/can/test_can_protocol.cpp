// SPDX-License-Identifier: MIT
// The CAN protocol in code: every telemetry signal round-trips at the edges of
// its range, the encoder sends each message at its rate with a rolling
// sequence counter, and the bus load of the default rates is below half the bus.
#include <cmath>
#include <cstdint>
#include <limits>

#include "firmware/can/messages.hpp"
#include "firmware/can/telemetry.hpp"

#include "support/cpputest.hpp"

using namespace hrg::fw::can;
using hrg::hal::CanFrame;

namespace {

// Edge values of a signal: the range ends, one LSB inside them, and zero when in range.
int edge_values(const SignalDef& s, double* out) {
  int n = 0;
  out[n++] = s.min;
  out[n++] = s.max;
  out[n++] = s.min + s.factor;
  out[n++] = s.max - s.factor;
  if (s.min < 0 && s.max > 0) out[n++] = 0.0;
  return n;
}

// The signals beside `s` in a frame: on its page (a multiplexed message),
// the multiplexor itself left out (it holds the page).
bool beside(const SignalDef& s, const SignalDef& o) {
  if (&o == &s || o.mux == MuxRole::multiplexor) return false;
  return s.mux == MuxRole::multiplexor ? o.mux == MuxRole::plain : on_page(o, s.mux_value);
}

void check_all_edges(const MessageDef& m) {
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    const SignalDef& s = m.signals[i];
    double edges[5];
    const int n = edge_values(s, edges);
    for (int e = 0; e < n; ++e) {
      // Every other signal of its page at its maximum: a layout overlap
      // would corrupt it.
      CanFrame f;
      f.id = m.id;
      f.len = m.dlc;
      for (const auto& other : m.signals) {
        if (other.mux == MuxRole::multiplexor) encode_signal(other, s.mux_value, f);
        if (beside(s, other)) encode_signal(other, other.max, f);
      }
      encode_signal(s, edges[e], f);
      DOUBLES_EQUAL(edges[e], decode_signal(s, f), 0.5 * s.factor + 1e-12 * std::fabs(edges[e]));
      for (const auto& o : m.signals) {
        if (!beside(s, o)) continue;
        DOUBLES_EQUAL(o.max, decode_signal(o, f), 0.5 * o.factor + 1e-12 * std::fabs(o.max));
      }
    }
  }
}

}  // namespace

TEST_GROUP(CanSignals){};

TEST(CanSignals, EveryTelemetrySignalRoundTripsAtTheEdgesOfItsRange) {
  for (const auto& m : kTelemetry)
    check_all_edges(m);
}

TEST(CanSignals, EveryCommandAndReplySignalRoundTripsAtTheEdgesOfItsRange) {
  for (const auto& m : kCommands)
    check_all_edges(m);
  check_all_edges(kReply);
}

TEST(CanSignals, ValuesBeyondTheRangeSaturateAndNanEncodesAsZero) {
  const SignalDef& cx = telemetry_def(Tm::wave_x).signals[sig::cx_v];
  CanFrame f;
  encode_signal(cx, 100.0, f);
  DOUBLES_EQUAL(cx.max, decode_signal(cx, f), 1e-12);
  encode_signal(cx, -100.0, f);
  DOUBLES_EQUAL(cx.min, decode_signal(cx, f), 1e-12);
  encode_signal(cx, std::numeric_limits<double>::quiet_NaN(), f);
  DOUBLES_EQUAL(0.0, decode_signal(cx, f), 0.0);
  // quad_effort's range [-1, 1] is narrower than its 16-bit field.
  const SignalDef& q = telemetry_def(Tm::loops).signals[sig::quad_effort];
  encode_signal(q, 3.0, f);
  DOUBLES_EQUAL(1.0, decode_signal(q, f), 1e-12);
}

TEST(CanSignals, SignedFieldsUseTwosComplementLittleEndian) {
  // cx = -1 uV is raw -1: 24 bits all ones in bytes 0..2.
  const SignalDef& cx = telemetry_def(Tm::wave_x).signals[sig::cx_v];
  CanFrame f;
  encode_signal(cx, -1e-6, f);
  LONGS_EQUAL(0xFF, f.data[0]);
  LONGS_EQUAL(0xFF, f.data[1]);
  LONGS_EQUAL(0xFF, f.data[2]);
  LONGS_EQUAL(0x00, f.data[3]);
  // 0x123456 uV = 1.193046 V: least significant byte first.
  encode_signal(cx, 1.193046, f);
  LONGS_EQUAL(0x56, f.data[0]);
  LONGS_EQUAL(0x34, f.data[1]);
  LONGS_EQUAL(0x12, f.data[2]);
}

TEST_GROUP(Telemetry){};

TEST(Telemetry, SnapshotFieldsLandInTheirSignals) {
  // GIVEN a snapshot with a distinct in-range value in every field
  TelemetrySnapshot s;
  s.cx_v = 1.432790;
  s.sx_v = -0.003621;
  s.cy_v = 0.000607;
  s.sy_v = -0.000013;
  s.theta_a_rad = -0.7854;
  s.output_angle_rad = 12.3456789;
  s.pll_freq_hz = 4999.87310;
  s.pll_locked = true;
  s.quad_effort = -0.25;
  s.pump_v = 9.519;
  s.pump_phase_rad = 0.1234;
  s.agc_setpoint_v = 1.5;
  s.mode = hrg::fw::Mode::operate;
  s.exc_on = true;
  s.exc_line = true;
  s.fault_input = false;
  s.ident_active = true;
  s.comp_valid = true;
  s.cal_damping_refuted = true;
  s.faults = static_cast<uint16_t>(hrg::fw::fault_bit(hrg::fw::Fault::adc_stuck) |
                                   hrg::fw::fault_bit(hrg::fw::Fault::external));
  s.temp_c = 32.26;
  s.comp_reasons = 32 + 64;  // readout_in_damping, control_drift_withheld
  s.readout_damping_sigmas = 22.4;
  s.nu_per_s = 3.14159e-3;
  s.dnu_c_per_s = 1.57e-4;
  s.dnu_s_per_s = -2.3e-5;
  s.dw_c_rad_s = 1.5708e-3;
  s.dw_s_rad_s = -4.2e-4;
  s.cond_log10 = 3.5;
  s.coverage = 0.875;
  s.windows = 42;
  s.est_valid = true;
  s.overruns = 70000;  // saturates at 65535
  s.missed_ticks = 3;
  s.max_frame_us = 612;
  s.cpu_load_pct = 61.5;
  s.angular_gain = 0.554;
  s.window_period_s = 60.0;
  s.window_length_s = 2.5;
  s.can.tx_queue_full = 17;
  s.can.error_frames = 5;
  s.can.bus_off_events = 2;
  s.can.restarts = 2;
  s.can_state = hrg::hal::CanState::error_passive;
  // WHEN each message is encoded, THEN its signals read back the fields
  struct Expect {
    Tm m;
    const char* sig;
    double value;
  };
  const Expect expect[] = {
      {Tm::wave_x, "cx_v", 1.432790},
      {Tm::wave_x, "sx_v", -0.003621},
      {Tm::wave_x, "exc", 1},
      {Tm::wave_y, "cy_v", 0.000607},
      {Tm::wave_y, "sy_v", -0.000013},
      {Tm::angle, "theta_a_rad", -0.7854},
      {Tm::angle, "output_angle_rad", 12.3456789},
      {Tm::loops, "pll_freq_hz", 4999.87310},
      {Tm::loops, "pll_locked", 1},
      {Tm::loops, "quad_effort", -0.25},
      {Tm::pump, "pump_v", 9.519},
      {Tm::pump, "pump_phase_rad", 0.1234},
      {Tm::pump, "agc_setpoint_v", 1.5},
      {Tm::status, "mode", 3},
      {Tm::status, "exc_on", 1},
      {Tm::status, "exc_line", 1},
      {Tm::status, "fault_input", 0},
      {Tm::status, "ident_active", 1},
      {Tm::status, "comp_valid", 1},
      {Tm::status, "cal_withdrawn", 0},
      {Tm::status, "cal_damping_refuted", 1},
      {Tm::status, "cal_gap_refuted", 0},
      {Tm::status, "faults", 8 + 64},
      {Tm::status, "temp_c", 32.26},
      {Tm::status, "comp_reasons", 32 + 64},
      {Tm::est_damping, "nu_per_s", 3.14159e-3},
      {Tm::est_damping, "dnu_c_per_s", 1.57e-4},
      {Tm::est_damping, "dnu_s_per_s", -2.3e-5},
      {Tm::est_split, "dw_c_rad_s", 1.5708e-3},
      {Tm::est_split, "dw_s_rad_s", -4.2e-4},
      {Tm::est_quality, "cond_log10", 3.5},
      {Tm::est_quality, "coverage", 0.875},
      {Tm::est_quality, "windows", 42},
      {Tm::est_quality, "valid", 1},
      {Tm::est_quality, "readout_damping_sigmas", 22.4},
      {Tm::exec, "overruns", 65535},
      {Tm::exec, "missed_ticks", 3},
      {Tm::exec, "max_frame_us", 612},
      {Tm::exec, "cpu_load_pct", 61.5},
      {Tm::info, "protocol_version", kProtocolVersion},
      {Tm::info, "angular_gain", 0.554},
      {Tm::info, "window_period_s", 60.0},
      {Tm::info, "window_length_s", 2.5},
      {Tm::can_stats, "tx_queue_full", 17},
      {Tm::can_stats, "error_frames", 5},
      {Tm::can_stats, "bus_off_events", 2},
      {Tm::can_stats, "restarts", 2},
      {Tm::can_stats, "can_state", 2},
  };
  for (const auto& e : expect) {
    CanFrame f;
    encode_telemetry(e.m, s, 200, f);
    const MessageDef& m = telemetry_def(e.m);
    LONGS_EQUAL(m.id, f.id);
    LONGS_EQUAL(m.dlc, f.len);
    const SignalDef* sd = find_signal(m, e.sig);
    CHECK_TEXT(sd != nullptr, e.sig);
    DOUBLES_EQUAL(e.value, decode_signal(*sd, f), 0.5 * sd->factor);
    DOUBLES_EQUAL(200, decode_signal(*find_signal(m, "seq"), f), 0);
  }
}

TEST(Telemetry, EachMessageIsSentAtItsRateWithARollingSequenceCounter) {
  // GIVEN the default rates at the 1 kHz base frame
  TelemetryEncoder enc(TelemetryConfig::defaults(), hrg::fw::kBaseRateHz);
  CHECK(enc.config_ok());
  TelemetrySnapshot s;
  std::array<int, kTelemetryCount> count{};
  std::array<int, kTelemetryCount> last_seq{};
  last_seq.fill(-1);
  std::array<CanFrame, kTelemetryCount> out;
  // WHEN one second of base frames runs
  for (uint32_t k = 0; k < hrg::fw::kBaseRateHz; ++k) {
    const std::size_t n = enc.tick(s, out);
    for (std::size_t j = 0; j < n; ++j) {
      const MessageDef* m = find_message(out[j].id);
      CHECK(m != nullptr);
      const auto i = static_cast<std::size_t>(m - kTelemetry.data());
      const int seq = static_cast<int>(decode_raw(*find_signal(*m, "seq"), out[j]));
      // THEN each counter is the previous one plus one, modulo 256
      if (last_seq[i] >= 0) LONGS_EQUAL((last_seq[i] + 1) % 256, seq);
      last_seq[i] = seq;
      ++count[i];
    }
  }
  // THEN each message was sent rate_hz times: e.g. the angle 500 times, seq 499 % 256
  for (std::size_t i = 0; i < kTelemetryCount; ++i) {
    LONGS_EQUAL(kTelemetry[i].default_rate_hz, count[i]);
    LONGS_EQUAL((kTelemetry[i].default_rate_hz - 1) % 256, last_seq[i]);
  }
}

TEST(Telemetry, RatesAreConfigurableAndARateThatDoesNotDivideTheBaseIsRefused) {
  TelemetryConfig c = TelemetryConfig::defaults();
  c.rate_hz[static_cast<std::size_t>(Tm::wave_x)] = 1000;
  c.rate_hz[static_cast<std::size_t>(Tm::angle)] = 0;  // off
  c.rate_hz[static_cast<std::size_t>(Tm::wave_y)] = 1000;
  c.rate_hz[static_cast<std::size_t>(Tm::row)] = 1000;
  TelemetryEncoder enc(c, 1000);
  CHECK(enc.config_ok());
  TelemetrySnapshot s;
  std::array<CanFrame, kTelemetryCount> out;
  int wave_x = 0;
  int angle = 0;
  for (int k = 0; k < 100; ++k) {
    const std::size_t n = enc.tick(s, out);
    for (std::size_t j = 0; j < n; ++j) {
      wave_x += out[j].id == telemetry_def(Tm::wave_x).id ? 1 : 0;
      angle += out[j].id == telemetry_def(Tm::angle).id ? 1 : 0;
    }
  }
  LONGS_EQUAL(100, wave_x);
  LONGS_EQUAL(0, angle);
  c.rate_hz[static_cast<std::size_t>(Tm::wave_y)] = 1000;
  CHECK(c.valid(1000));
  c.rate_hz[static_cast<std::size_t>(Tm::wave_y)] = 500;  // halves of a sample must pair
  CHECK_FALSE(c.valid(1000));
  c.rate_hz[static_cast<std::size_t>(Tm::wave_y)] = 1000;
  c.rate_hz[static_cast<std::size_t>(Tm::row)] = 500;  // and the row that stamps them
  CHECK_FALSE(c.valid(1000));
  c.rate_hz[static_cast<std::size_t>(Tm::row)] = 1000;
  c.rate_hz[static_cast<std::size_t>(Tm::status)] = 3;  // 1000 / 3 is not whole
  CHECK_FALSE(c.valid(1000));
  TelemetryEncoder bad(c, 1000);
  CHECK_FALSE(bad.config_ok());
  LONGS_EQUAL(10, bad.config().rate_hz[static_cast<std::size_t>(Tm::status)]);
}

TEST(Telemetry, TheThreePartsOfARecordingRowGoOutInTheSameFrameWithTheSameSeq) {
  TelemetryEncoder enc(TelemetryConfig::defaults(), 1000);
  TelemetrySnapshot s;
  std::array<CanFrame, kTelemetryCount> out;
  int rows = 0;
  for (int k = 0; k < 1000; ++k) {
    s.cx_v = 1e-3 * k;
    s.cy_v = -1e-3 * k;
    s.row_t_s = 1e-3 * k;
    // The first 20 frames have no envelope reference yet: nothing of a row.
    s.row_ready = k >= 20;
    const std::size_t n = enc.tick(s, out);
    const CanFrame* x = nullptr;
    const CanFrame* y = nullptr;
    const CanFrame* r = nullptr;
    for (std::size_t j = 0; j < n; ++j) {
      if (out[j].id == telemetry_def(Tm::wave_x).id) x = &out[j];
      if (out[j].id == telemetry_def(Tm::wave_y).id) y = &out[j];
      if (out[j].id == telemetry_def(Tm::row).id) r = &out[j];
    }
    CHECK((x == nullptr) == (y == nullptr));
    CHECK((x == nullptr) == (r == nullptr));
    if (x == nullptr) continue;
    CHECK(k >= 20);
    ++rows;
    const MessageDef& mx = telemetry_def(Tm::wave_x);
    const MessageDef& my = telemetry_def(Tm::wave_y);
    const MessageDef& mr = telemetry_def(Tm::row);
    const auto seq = decode_raw(mx.signals[sig::wave_x_seq], *x);
    LONGS_EQUAL(seq, decode_raw(my.signals[sig::wave_y_seq], *y));
    LONGS_EQUAL(seq, decode_raw(mr.signals[sig::row_seq], *r));
    DOUBLES_EQUAL(-decode_signal(mx.signals[sig::cx_v], *x),
                  decode_signal(my.signals[sig::cy_v], *y), 1e-9);
    DOUBLES_EQUAL(decode_signal(mx.signals[sig::cx_v], *x),
                  decode_signal(mr.signals[sig::row_t_s], *r), 1e-9);
  }
  // 100 Hz from frame 20 on (the encoder's period does not restart).
  LONGS_EQUAL(98, rows);
}

TEST(Telemetry, DefaultBusLoadIsTheSumOfRateTimesWorstCaseFrameBits) {
  // 8 data bytes: 47 + 64 + floor(97 / 4) = 135 bits; 7 bytes: 47 + 56 + 22 = 125 bits.
  LONGS_EQUAL(135, worst_case_frame_bits(8));
  LONGS_EQUAL(125, worst_case_frame_bits(7));
  LONGS_EQUAL(105, worst_case_frame_bits(5));
  // angle (7 B) at 500 Hz; wave x, y, row and loops (8 B), pump (7 B) at 100 Hz;
  // status, exec and cal readings (8 B) at 10 Hz; estimator 8+7+8 B at 2 Hz; info,
  // can stats (8 B) and reference (5 B) at 1 Hz.
  const double bits = 500.0 * 125 + 100.0 * (135 + 135 + 135 + 135 + 125) +
                      10.0 * (135 + 135 + 135) + 2.0 * (135 + 125 + 135) + 1.0 * (135 + 135 + 105);
  const double load = bus_load_fraction(TelemetryConfig::defaults(), kBitrateBps);
  DOUBLES_EQUAL(bits / 1e6, load, 1e-12);
  DOUBLES_EQUAL(0.134215, load, 1e-6);
  CHECK(load < 0.5);
}

namespace {

FirmwareEstimates some_readings() {
  FirmwareEstimates e;
  e.feedthrough = true;
  e.edges = 34;
  e.feedthrough_residual_v_per_v = {4.019e-4, 6.925e-4, -1.2e-5, 7.5e-6};
  e.feedthrough_in_force_v_per_v = {-0.1, 0.1, 8.0e-4, -3.14e-7};
  e.feedthrough_sigma_v_per_v = 2.7e-6;
  e.feedthrough_scatter_v_per_v = 1.7e-6;
  e.in_force_s = 1796.25;
  e.thermal_damping = true;
  e.thermal_damping_per_c = -0.00391;
  e.thermal_damping_sigma_per_c = 1.5e-4;
  // The pickoff self-calibration's map: the -1 deg misalignment row's, the
  // phase at the calibration's range end (20 deg).
  e.pickoff = true;
  e.pickoff_gain = -1.3582e-5;
  e.pickoff_gain_sigma = 1.5586e-5;
  e.pickoff_misalignment_rad = -0.0174577920;
  e.pickoff_misalignment_sigma_rad = 6.1069e-6;
  e.pickoff_phase_rad = 0.3490658504;
  e.pickoff_phase_sigma_rad = 1.2957e-5;
  return e;
}

double read(const CanFrame& f, const char* name) {
  return decode_signal(*find_signal(telemetry_def(Tm::cal_readings), name), f);
}

}  // namespace

TEST(Telemetry, TheCalibrationReadingsGoOutAsOneSetOfTenPagesFromTheSameReadings) {
  // GIVEN the default rates and the firmware's readings in the snapshot
  TelemetryEncoder enc(TelemetryConfig::defaults(), 1000);
  TelemetrySnapshot s;
  s.estimates = some_readings();
  std::array<CanFrame, kTelemetryCount> out;
  std::array<CanFrame, kCalReadingsPages> set{};
  int pages = 0;
  int due_seen = 0;
  // WHEN 1 s of base frames run, the readings changed after the set began
  for (int k = 0; k < 1000; ++k) {
    const bool due = enc.cal_readings_due();
    due_seen += due ? 1 : 0;
    if (k == 150) s.estimates.edges = 35;  // held: the set keeps 34
    const std::size_t n = enc.tick(s, out);
    for (std::size_t j = 0; j < n; ++j) {
      if (out[j].id != telemetry_def(Tm::cal_readings).id) continue;
      // THEN page i is the i-th frame of the message (seq i), the first
      // announced by cal_readings_due
      LONGS_EQUAL(pages, static_cast<long>(read(out[j], "page")));
      LONGS_EQUAL(pages, static_cast<long>(read(out[j], "seq")));
      if (pages == 0) CHECK(due);
      set[static_cast<std::size_t>(pages++)] = out[j];
    }
  }
  LONGS_EQUAL(kCalReadingsPages, pages);
  LONGS_EQUAL(1, due_seen);
  // ... and every reading is back within half its resolution
  const FirmwareEstimates e = some_readings();
  LONGS_EQUAL(34, static_cast<long>(read(set[0], "pump_edge_edges")));
  DOUBLES_EQUAL(e.in_force_s, read(set[0], "pump_edge_in_force_s"), 0.005);
  const double ft = 1e-8;  // half of 2e-8 V/V
  DOUBLES_EQUAL(e.feedthrough_residual_v_per_v.x_re, read(set[1], "pump_edge_x_re_v_per_v"), ft);
  DOUBLES_EQUAL(e.feedthrough_residual_v_per_v.x_im, read(set[1], "pump_edge_x_im_v_per_v"), ft);
  DOUBLES_EQUAL(e.feedthrough_residual_v_per_v.y_re, read(set[2], "pump_edge_y_re_v_per_v"), ft);
  DOUBLES_EQUAL(e.feedthrough_residual_v_per_v.y_im, read(set[2], "pump_edge_y_im_v_per_v"), ft);
  DOUBLES_EQUAL(e.feedthrough_sigma_v_per_v, read(set[3], "pump_edge_sigma_v_per_v"), 5e-10);
  DOUBLES_EQUAL(e.feedthrough_scatter_v_per_v, read(set[3], "pump_edge_scatter_v_per_v"), 5e-10);
  // the calibration's own range ends (+-0.1 V/V) fit
  DOUBLES_EQUAL(-0.1, read(set[4], "pump_edge_in_force_x_re_v_per_v"), ft);
  DOUBLES_EQUAL(0.1, read(set[4], "pump_edge_in_force_x_im_v_per_v"), ft);
  DOUBLES_EQUAL(8.0e-4, read(set[5], "pump_edge_in_force_y_re_v_per_v"), ft);
  DOUBLES_EQUAL(-3.14e-7, read(set[5], "pump_edge_in_force_y_im_v_per_v"), ft);
  DOUBLES_EQUAL(e.thermal_damping_per_c, read(set[6], "thermal_damping_per_c"), 5e-8);
  DOUBLES_EQUAL(e.thermal_damping_sigma_per_c, read(set[6], "thermal_damping_sigma_per_c"), 5e-9);
  const double map = 2e-9;  // half of 4e-9 (-, rad)
  const double map_sigma = 1e-9;
  DOUBLES_EQUAL(e.pickoff_gain, read(set[7], "self_cal_gain"), map);
  DOUBLES_EQUAL(e.pickoff_gain_sigma, read(set[7], "self_cal_gain_sigma"), map_sigma);
  DOUBLES_EQUAL(e.pickoff_misalignment_rad, read(set[8], "self_cal_misalignment_rad"), map);
  DOUBLES_EQUAL(e.pickoff_misalignment_sigma_rad, read(set[8], "self_cal_misalignment_sigma_rad"),
                map_sigma);
  DOUBLES_EQUAL(e.pickoff_phase_rad, read(set[9], "self_cal_phase_rad"), map);
  DOUBLES_EQUAL(e.pickoff_phase_sigma_rad, read(set[9], "self_cal_phase_sigma_rad"), map_sigma);
  for (const auto& f : set) {
    DOUBLES_EQUAL(1, read(f, "thermal_valid"), 0);
    DOUBLES_EQUAL(1, read(f, "self_cal_valid"), 0);
  }
}

TEST(Telemetry, APickoffSigmaAboveItsRangeSaturatesAtTheRangesEnd) {
  // GIVEN a gain sigma of 0.01, above the signal's 2.1e-3
  FirmwareEstimates e = some_readings();
  e.pickoff_gain_sigma = 0.01;
  CanFrame f;
  encode_cal_readings(e, 7, 0, f);
  // THEN it reads as the range's end, (2^20 - 1) 2e-9, the gain untouched
  DOUBLES_EQUAL(1048575 * 2e-9, read(f, "self_cal_gain_sigma"), 1e-15);
  DOUBLES_EQUAL(e.pickoff_gain, read(f, "self_cal_gain"), 2e-9);
}

TEST(Telemetry, NoReadingIsSentAsNoEdgesAndNeitherThermalNorPickoffMapValid) {
  FirmwareEstimates e = some_readings();
  e.feedthrough = false;
  e.thermal_damping = false;
  e.pickoff = false;
  for (uint8_t page = 0; page < kCalReadingsPages; ++page) {
    CanFrame f;
    encode_cal_readings(e, page, 3, f);
    LONGS_EQUAL(page, static_cast<long>(read(f, "page")));
    DOUBLES_EQUAL(0, read(f, "thermal_valid"), 0);
    DOUBLES_EQUAL(0, read(f, "self_cal_valid"), 0);
    // Every byte but the page/flags byte and seq is zero: nothing stale.
    for (int b = 1; b < 7; ++b)
      LONGS_EQUAL(0, f.data[b]);
  }
}
