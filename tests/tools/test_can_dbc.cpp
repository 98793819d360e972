// SPDX-License-Identifier: MIT
// The DBC file and the code agree: every message and signal of the code is in
// firmware/can/hrg.dbc with the same layout, scaling, range and rate, and the
// DBC has nothing else. The bus load is computed from the DBC alone.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "can/dbc.hpp"
#include "firmware/can/calibration_transfer.hpp"
#include "firmware/can/command.hpp"
#include "firmware/can/messages.hpp"
#include "firmware/can/telemetry.hpp"

#include "support/cpputest.hpp"

using namespace hrg::fw::can;

namespace {

std::string source_dir() {
  const char* d = std::getenv("HRG_SOURCE_DIR");
  return d != nullptr ? d : ".";
}

// Loaded before main so CppUTest's leak checker does not see the allocation.
const hrg::can::Dbc kDbc = hrg::can::load_dbc(source_dir() + "/firmware/can/hrg.dbc");
const hrg::can::Dbc& dbc() { return kDbc; }

void check_message(const MessageDef& m, const hrg::can::Dbc& d) {
  const hrg::can::DbcMessage* dm = d.message(m.id);
  CHECK_TEXT(dm != nullptr, m.name);
  STRCMP_EQUAL(m.name, dm->name.c_str());
  LONGS_EQUAL(m.dlc, dm->dlc);
  STRCMP_EQUAL(m.sender, dm->sender.c_str());
  CHECK_FALSE(dm->extended);
  LONGS_EQUAL(m.signals.size(), dm->signals.size());
  for (const auto& s : m.signals) {
    const hrg::can::DbcSignal* ds = dm->signal(s.name);
    CHECK_TEXT(ds != nullptr, s.name);
    LONGS_EQUAL(s.start_bit, ds->start_bit);
    LONGS_EQUAL(s.length, ds->length);
    CHECK_EQUAL(s.is_signed, ds->is_signed);
    DOUBLES_EQUAL(s.factor, ds->factor, 1e-12 * s.factor);
    DOUBLES_EQUAL(s.offset, ds->offset, 1e-12);
    DOUBLES_EQUAL(s.min, ds->min, 1e-9 * (1 + std::fabs(s.min)));
    DOUBLES_EQUAL(s.max, ds->max, 1e-9 * (1 + std::fabs(s.max)));
    STRCMP_EQUAL(s.unit, ds->unit.c_str());
    CHECK_EQUAL(s.mux == MuxRole::multiplexor, ds->multiplexor);
    CHECK_EQUAL(s.mux == MuxRole::multiplexed, ds->mux_value.has_value());
    if (ds->mux_value) LONGS_EQUAL(s.mux_value, *ds->mux_value);
  }
  if (m.default_rate_hz != 0) {
    CHECK_TEXT(dm->cycle_time_ms.has_value(), m.name);
    LONGS_EQUAL(1000 / m.default_rate_hz, *dm->cycle_time_ms);
  } else {
    CHECK_TEXT(!dm->cycle_time_ms.has_value() || *dm->cycle_time_ms == 0, m.name);
  }
}

// Worst-case stuffed length of a classic frame with an 11-bit identifier, from
// the frame layout: SOF 1, id 11, RTR 1, IDE 1, r0 1, DLC 4, data 8n, CRC 15 are
// stuffed (34 + 8n bits, one stuff bit per 4 after the first); then CRC
// delimiter 1, ACK 2, EOF 7 and the 3-bit interframe space.
unsigned frame_bits(unsigned dlc) {
  const unsigned stuffed = 34 + 8 * dlc;
  return stuffed + (stuffed - 1) / 4 + 1 + 2 + 7 + 3;
}

double dbc_bus_load(const hrg::can::Dbc& d) {
  double bits_per_s = 0;
  for (const auto& m : d.messages) {
    if (!m.cycle_time_ms || *m.cycle_time_ms == 0) continue;
    bits_per_s += 1000.0 / *m.cycle_time_ms * frame_bits(m.dlc);
  }
  return bits_per_s / d.bitrate_bps;
}

}  // namespace

TEST_GROUP(DbcAgreesWithCode){};

TEST(DbcAgreesWithCode, EveryMessageAndSignalOfTheCodeIsInTheDbc) {
  for (const auto& m : kTelemetry)
    check_message(m, dbc());
  for (const auto& m : kCommands)
    check_message(m, dbc());
  check_message(kReply, dbc());
  for (const auto& m : kCalibrationMessages)
    check_message(m, dbc());
  check_message(kLabTable, dbc());
}

TEST(DbcAgreesWithCode, TheDbcHasNoMessageTheCodeDoesNotKnow) {
  LONGS_EQUAL(kTelemetryCount + kCommandCount + 1 + kCalibrationMessageCount + 1,
              dbc().messages.size());
  for (const auto& m : dbc().messages)
    CHECK_TEXT(find_message(m.id) != nullptr, m.name.c_str());
}

TEST(DbcAgreesWithCode, ModeValuesInTheDbcAreTheFirmwareModes) {
  const auto* status = dbc().message("HRG_STATUS");
  CHECK(status != nullptr);
  const auto& values = status->signal("mode")->values;
  STRCMP_EQUAL("operate", values.at(static_cast<int>(hrg::fw::Mode::operate)).c_str());
  STRCMP_EQUAL("free_decay", values.at(static_cast<int>(hrg::fw::Mode::free_decay)).c_str());
  STRCMP_EQUAL("safe", values.at(static_cast<int>(hrg::fw::Mode::safe)).c_str());
  const auto& results = dbc().message("HRG_CMD_REPLY")->signal("result")->values;
  for (int r = 0; r <= 8; ++r) {
    STRCMP_EQUAL(to_string(static_cast<CommandResult>(r)), results.at(r).c_str());
  }
  const auto& cal = dbc().message("HRG_CAL_REPLY")->signal("result")->values;
  LONGS_EQUAL(kCalResultCount, cal.size());
  for (int r = 0; r < static_cast<int>(kCalResultCount); ++r) {
    STRCMP_EQUAL(to_string(static_cast<CalResult>(r)), cal.at(r).c_str());
  }
}

TEST(DbcAgreesWithCode, FramesEncodedByTheFirmwareDecodeThroughTheDbc) {
  TelemetrySnapshot s;
  s.cx_v = -1.234567;
  s.sy_v = 8.0;
  s.output_angle_rad = -3.1415926;
  s.pll_freq_hz = 5003.54648;
  s.temp_c = -40.25;
  s.dw_s_rad_s = -0.0123;
  hrg::hal::CanFrame f;
  encode_telemetry(Tm::wave_x, s, 7, f);
  DOUBLES_EQUAL(-1.234567, dbc().message(f.id)->signal("cx_v")->decode(f), 1e-12);
  encode_telemetry(Tm::wave_y, s, 7, f);
  DOUBLES_EQUAL(8.0, dbc().message(f.id)->signal("sy_v")->decode(f), 1e-12);
  encode_telemetry(Tm::angle, s, 7, f);
  DOUBLES_EQUAL(-3.1415926, dbc().message(f.id)->signal("output_angle_rad")->decode(f), 1e-12);
  encode_telemetry(Tm::loops, s, 7, f);
  DOUBLES_EQUAL(5003.54648, dbc().message(f.id)->signal("pll_freq_hz")->decode(f), 1e-9);
  encode_telemetry(Tm::status, s, 7, f);
  DOUBLES_EQUAL(-40.25, dbc().message(f.id)->signal("temp_c")->decode(f), 1e-9);
  encode_telemetry(Tm::est_split, s, 7, f);
  DOUBLES_EQUAL(-0.0123, dbc().message(f.id)->signal("dw_s_rad_s")->decode(f), 1e-12);
  DOUBLES_EQUAL(7, dbc().message(f.id)->signal("seq")->decode(f), 0);
  s.row_t_s = 3599.9995;
  s.row_pump_v = 9.518;
  s.row_exc = false;
  encode_telemetry(Tm::row, s, 9, f);
  DOUBLES_EQUAL(3599.9995, dbc().message(f.id)->signal("t_s")->decode(f), 1e-9);
  DOUBLES_EQUAL(9.518, dbc().message(f.id)->signal("pump_v")->decode(f), 1e-12);
  DOUBLES_EQUAL(0, dbc().message(f.id)->signal("exc")->decode(f), 0);
  s.f_ref_hz = 4999.87312;
  encode_telemetry(Tm::reference, s, 9, f);
  DOUBLES_EQUAL(4999.87312, dbc().message(f.id)->signal("f_ref_hz")->decode(f), 1e-9);
  // HRG_CAL_READINGS: each page's signals through the DBC, present only on
  // their page.
  s.estimates.feedthrough = true;
  s.estimates.edges = 34;
  s.estimates.in_force_s = 1799.99;
  s.estimates.feedthrough_residual_v_per_v = {4.019e-4, 6.925e-4, 6.932e-4, -4.025e-4};
  s.estimates.feedthrough_sigma_v_per_v = 2.7e-6;
  s.estimates.feedthrough_in_force_v_per_v = {0.1, -0.1, 0, 3.998e-4};
  s.estimates.thermal_damping = true;
  s.estimates.thermal_damping_per_c = 0.2;
  s.estimates.thermal_damping_sigma_per_c = 1.5e-4;
  s.estimates.pickoff = true;
  s.estimates.pickoff_gain = -0.2;
  s.estimates.pickoff_gain_sigma = 6e-7;
  s.estimates.pickoff_misalignment_rad = -0.0174578;
  s.estimates.pickoff_misalignment_sigma_rad = 6.1e-6;
  s.estimates.pickoff_phase_rad = 0.349;
  s.estimates.pickoff_phase_sigma_rad = 1.3e-5;
  const auto* readings = dbc().message("HRG_CAL_READINGS");
  CHECK(readings != nullptr);
  const auto at = [&](uint8_t page, const char* name) {
    encode_cal_readings(s.estimates, page, 5, f);
    const auto* sig = readings->signal(name);
    CHECK_TEXT(readings->present(*sig, f), name);
    return sig->decode(f);
  };
  DOUBLES_EQUAL(34, at(0, "pump_edge_edges"), 0);
  DOUBLES_EQUAL(1799.99, at(0, "pump_edge_in_force_s"), 1e-9);
  DOUBLES_EQUAL(6.932e-4, at(2, "pump_edge_y_re_v_per_v"), 1e-8);
  DOUBLES_EQUAL(2.7e-6, at(3, "pump_edge_sigma_v_per_v"), 5e-10);
  DOUBLES_EQUAL(-0.1, at(4, "pump_edge_in_force_x_im_v_per_v"), 1e-8);
  DOUBLES_EQUAL(3.998e-4, at(5, "pump_edge_in_force_y_im_v_per_v"), 1e-8);
  DOUBLES_EQUAL(0.2, at(6, "thermal_damping_per_c"), 5e-8);
  DOUBLES_EQUAL(1, at(6, "thermal_valid"), 0);
  DOUBLES_EQUAL(-0.2, at(7, "self_cal_gain"), 2e-9);
  DOUBLES_EQUAL(6e-7, at(7, "self_cal_gain_sigma"), 1e-9);
  DOUBLES_EQUAL(-0.0174578, at(8, "self_cal_misalignment_rad"), 2e-9);
  DOUBLES_EQUAL(6.1e-6, at(8, "self_cal_misalignment_sigma_rad"), 1e-9);
  DOUBLES_EQUAL(0.349, at(9, "self_cal_phase_rad"), 2e-9);
  DOUBLES_EQUAL(1.3e-5, at(9, "self_cal_phase_sigma_rad"), 1e-9);
  DOUBLES_EQUAL(1, at(9, "self_cal_valid"), 0);
  encode_cal_readings(s.estimates, 1, 5, f);
  CHECK_FALSE(readings->present(*readings->signal("pump_edge_edges"), f));
  CHECK(readings->present(*readings->signal("seq"), f));
  f = encode_lab_table(-123.456789, 31.27, 3);
  DOUBLES_EQUAL(-123.456789, dbc().message(f.id)->signal("rate_dps")->decode(f), 1e-12);
  DOUBLES_EQUAL(31.27, dbc().message(f.id)->signal("temp_c")->decode(f), 1e-9);
}

TEST(DbcAgreesWithCode, BusLoadFromTheDbcIsBelowHalfAndMatchesCodeAndReadme) {
  LONGS_EQUAL(kBitrateBps, dbc().bitrate_bps);
  const double load = dbc_bus_load(dbc());
  DOUBLES_EQUAL(bus_load_fraction(TelemetryConfig::defaults(), kBitrateBps), load, 1e-12);
  CHECK(load < 0.5);
  // The README states the figure to two decimals in percent.
  std::ifstream in(source_dir() + "/firmware/can/README.md");
  CHECK_TEXT(in.good(), "firmware/can/README.md missing");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const std::string key = "Bus load at the default rates: ";
  const auto at = text.find(key);
  CHECK_TEXT(at != std::string::npos, "README does not state the bus load");
  const double stated_pct = std::strtod(text.c_str() + at + key.size(), nullptr);
  DOUBLES_EQUAL(100.0 * load, stated_pct, 0.005);
}

TEST_GROUP(DbcParser){};

TEST(DbcParser, AMalformedSignalIsReportedWithItsLine) {
  const char* text =
      "BS_: 1000000\n"
      "BO_ 256 A: 8 HRG\n"
      " SG_ x : 0|8@1+ (1,0) [0|255] \"\" HOST\n"
      " SG_ y : 8|8@0+ (1,0) [0|255] \"\" HOST\n";
  try {
    hrg::can::parse_dbc(text, "t.dbc");
    FAIL("no error for a Motorola-order signal");
  } catch (const hrg::can::DbcError& e) {
    STRCMP_CONTAINS("t.dbc:4:", e.what());
    STRCMP_CONTAINS("Intel", e.what());
  }
  try {
    hrg::can::parse_dbc("BO_ 256 A: 9 HRG\n", "u.dbc");
    FAIL("no error for DLC 9");
  } catch (const hrg::can::DbcError& e) {
    STRCMP_CONTAINS("u.dbc:1:", e.what());
  }
}

TEST(DbcParser, MultiplexedSignalsAreReadWithTheirPage) {
  const auto d = hrg::can::parse_dbc(
      "BO_ 270 R: 8 HRG\n"
      " SG_ a m1 : 8|8@1+ (1,0) [0|255] \"\" HOST\n"
      " SG_ page M : 0|4@1+ (1,0) [0|6] \"\" HOST\n"
      " SG_ b m0 : 8|16@1- (0.5,0) [-16384|16383.5] \"\" HOST\n");
  const auto* m = d.message(270u);
  CHECK(m->multiplexor() == m->signal("page"));
  LONGS_EQUAL(1, *m->signal("a")->mux_value);
  LONGS_EQUAL(0, *m->signal("b")->mux_value);
  CHECK_FALSE(m->signal("page")->mux_value.has_value());
  hrg::hal::CanFrame f;
  f.data[0] = 1;
  f.data[1] = 42;
  CHECK(m->present(*m->signal("a"), f));
  CHECK_FALSE(m->present(*m->signal("b"), f));
  DOUBLES_EQUAL(42, m->signal("a")->decode(f), 0);
}

TEST(DbcParser, BadMultiplexingIsReportedWithItsLine) {
  const auto error = [](const char* text) {
    try {
      hrg::can::parse_dbc(text, "m.dbc");
    } catch (const hrg::can::DbcError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // a page with no multiplexor in the message
  std::string e = error("BO_ 1 A: 8 HRG\n SG_ x m2 : 8|8@1+ (1,0) [0|255] \"\" HOST\n");
  STRCMP_CONTAINS("m.dbc:2:", e.c_str());
  STRCMP_CONTAINS("no multiplexor", e.c_str());
  // extended multiplexing (a multiplexed multiplexor)
  e = error("BO_ 1 A: 8 HRG\n SG_ x m2M : 8|8@1+ (1,0) [0|255] \"\" HOST\n");
  STRCMP_CONTAINS("m.dbc:2:", e.c_str());
  STRCMP_CONTAINS("extended multiplexing", e.c_str());
  // two multiplexors
  e = error(
      "BO_ 1 A: 8 HRG\n SG_ x M : 0|4@1+ (1,0) [0|15] \"\" HOST\n"
      " SG_ y M : 4|4@1+ (1,0) [0|15] \"\" HOST\n");
  STRCMP_CONTAINS("m.dbc:3:", e.c_str());
  STRCMP_CONTAINS("second multiplexor", e.c_str());
}

TEST(DbcParser, ExtendedIdentifiersAndCycleTimesAreRead) {
  const auto d = hrg::can::parse_dbc(
      "BO_ 2147483905 E: 4 HRG\n SG_ v : 4|12@1- (0.5,-1) [-1025|1022.5] \"m\" HOST\n\n"
      "BA_ \"GenMsgCycleTime\" BO_ 2147483905 20;\n");
  const auto* m = d.message(0x101u);
  CHECK(m != nullptr);
  CHECK(m->extended);
  LONGS_EQUAL(20, *m->cycle_time_ms);
  const auto* v = m->signal("v");
  CHECK(v->is_signed);
  DOUBLES_EQUAL(-1.0, v->offset, 0);
  hrg::hal::CanFrame f;
  f.data[0] = 0xF0;  // raw = 0xFFF = -1 -> -1.5
  f.data[1] = 0xFF;
  DOUBLES_EQUAL(-1.5, v->decode(f), 0);
}
