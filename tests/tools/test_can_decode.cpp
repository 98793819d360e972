// SPDX-License-Identifier: MIT
// `hrg can-decode`: a candump log of the firmware's telemetry, with frames
// removed as a bus would lose them, becomes an hrg-recording v1 whose rows are
// the transmitted samples and whose metadata counts exactly the removed frames.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

#include "can/can_decode.hpp"
#include "can/candump_log.hpp"
#include "firmware/can/messages.hpp"
#include "firmware/can/telemetry.hpp"
#include "recording/recording.hpp"

#include "support/cpputest.hpp"

using namespace hrg::fw::can;

namespace {

constexpr uint64_t kT0Ns = 1'700'000'000'000'000'000ull;  // an epoch-like log start

TelemetrySnapshot sample(int k) {
  TelemetrySnapshot s;
  const double t = 1e-3 * k;
  s.cx_v = 1.2 * std::cos(0.3 * t);
  s.sx_v = 0.01 * std::sin(0.3 * t);
  s.cy_v = -0.004 * t;
  s.sy_v = 1e-5 * k;
  s.exc_on = (k / 400) % 2 == 0;
  s.row_exc = ((k - 7) / 400) % 2 == 0;  // the drive as applied lags the command
  s.row_t_s = 0.1 + 1e-3 * k - 2.5e-3;   // the envelope's centre, 0.1 s after boot
  s.f_ref_hz = 4999.87312;
  s.pump_v = 9.5 + 1e-3 * k;
  s.row_pump_v = 9.4 + 1e-3 * k;  // the pump the row's envelopes saw, not the one written next
  s.temp_c = 31.25;
  s.pll_freq_hz = 4999.87310 + 1e-4 * k;
  s.angular_gain = 0.554;
  s.mode = hrg::fw::Mode::operate;
  // The compensation: not checked yet, then the model check against the
  // readout's pattern trips from frame 1000 on (12.5 sigmas, D_Phi withheld).
  s.comp_reasons = k < 1000 ? 4 : 32 + 64;
  s.readout_damping_sigmas = k < 1000 ? 0.0 : 12.5;
  // The firmware's readings: one more edge every 100 ms.
  FirmwareEstimates& e = s.estimates;
  e.feedthrough = true;
  e.edges = 1 + static_cast<uint32_t>(k / 100);
  e.in_force_s = 1e-3 * k;
  e.feedthrough_residual_v_per_v = {4e-4 + 1e-7 * k, 6.9e-4, 6.9e-4, -4e-4};
  e.feedthrough_in_force_v_per_v = {1e-5, 0, 0, -2e-5};
  e.feedthrough_sigma_v_per_v = 2.7e-6;
  e.feedthrough_scatter_v_per_v = 1.7e-6;
  e.thermal_damping = true;
  e.thermal_damping_per_c = 0.0039;
  e.thermal_damping_sigma_per_c = 1.5e-4;
  e.pickoff = true;
  e.pickoff_gain = 0.01 + 1e-8 * k;
  e.pickoff_gain_sigma = 6e-7;
  e.pickoff_misalignment_rad = -0.0174578;
  e.pickoff_misalignment_sigma_rad = 6.1e-6;
  e.pickoff_phase_rad = 0.0174533;
  e.pickoff_phase_sigma_rad = 1.3e-5;
  return s;
}

// The bench's rate at frame k (LAB_TABLE, logged after the frame's telemetry).
double table_rate_dps(int k) { return 0.01 * k; }

// Two seconds of default-rate telemetry, LAB_TABLE frames at the row rate
// when `lab`; drops the frames for which `drop` says so (message index,
// occurrence).
std::string write_log(const std::set<std::pair<int, int>>& drop, bool lab = true) {
  const std::string path = "test_can_decode.log";
  hrg::can::CandumpLogWriter w(path);
  TelemetryEncoder enc(TelemetryConfig::defaults(), 1000);
  std::array<hrg::hal::CanFrame, kTelemetryCount> out;
  std::array<int, kTelemetryCount> seen{};
  uint8_t lab_seq = 0;
  for (int k = 0; k < 2000; ++k) {
    const std::size_t n = enc.tick(sample(k), out);
    for (std::size_t j = 0; j < n; ++j) {
      const auto i = static_cast<int>(find_message(out[j].id) - kTelemetry.data());
      if (drop.count({i, seen[i]++}) == 0) w.write(out[j], kT0Ns + 1'000'000ull * k + 10 * j);
    }
    if (lab && k % 10 == 9) {
      w.write(encode_lab_table(table_rate_dps(k + 1), 24.5, lab_seq++),
              kT0Ns + 1'000'000ull * k + 500);
    }
  }
  return path;
}

hrg::can::CanDecodeOptions options(const std::string& log, const std::string& out) {
  hrg::can::CanDecodeOptions o;
  o.log_path = log;
  o.out_path = out;
  o.dbc_path = std::string(std::getenv("HRG_SOURCE_DIR")) + "/firmware/can/hrg.dbc";
  return o;
}

}  // namespace

TEST_GROUP(CanDecode){};

TEST(CanDecode, RowsAreTheTransmittedSamplesAndLossesAreCountedPerMessage) {
  // GIVEN a log that lost WAVE_X #10, WAVE_Y #30, #31, #32, ROW #50 and LOOPS #50, #51
  const int wx = static_cast<int>(Tm::wave_x);
  const int wy = static_cast<int>(Tm::wave_y);
  const int rw = static_cast<int>(Tm::row);
  const int lp = static_cast<int>(Tm::loops);
  const std::string log =
      write_log({{wx, 10}, {wy, 30}, {wy, 31}, {wy, 32}, {rw, 50}, {lp, 50}, {lp, 51}});
  const hrg::can::CanDecodeOptions o = options(log, "test_can_decode.csv");
  // WHEN it is decoded
  const hrg::can::CanDecodeSummary s = hrg::can::can_decode(o);
  // THEN 200 samples less the 5 incomplete ones are rows
  LONGS_EQUAL(195, s.rows);
  LONGS_EQUAL(1, s.messages.at("HRG_WAVE_X").lost);
  LONGS_EQUAL(3, s.messages.at("HRG_WAVE_Y").lost);
  LONGS_EQUAL(1, s.messages.at("HRG_ROW").lost);
  LONGS_EQUAL(2, s.messages.at("HRG_LOOPS").lost);
  LONGS_EQUAL(0, s.messages.at("HRG_ANGLE").lost);
  DOUBLES_EQUAL(0.554, s.angular_gain, 1e-12);
  // The reference is HRG_REFERENCE's, not the PLL's frequency.
  DOUBLES_EQUAL(4999.87312, s.f_ref_hz, 1e-9);
  CHECK(s.has_lab_table);
  const hrg::recording::Recording rec = hrg::recording::read_recording(o.out_path);
  LONGS_EQUAL(195, rec.rows());
  DOUBLES_EQUAL(4999.87312, rec.f_ref_hz(), 1e-9);
  STRCMP_EQUAL("1 of 200", rec.metadata_value("can_lost_HRG_WAVE_X").c_str());
  STRCMP_EQUAL("3 of 200", rec.metadata_value("can_lost_HRG_WAVE_Y").c_str());
  // AND each row holds the sample of its frame at the firmware's row time
  // (k = 10 m, t_s = 0.1 s + k ms - 2.5 ms), whatever the log's timestamps: the
  // envelopes, the drive as applied, its command, the pump of that frame and
  // the table's rate logged after it.
  const auto& t = rec.column("t_s");
  for (std::size_t r = 0; r < rec.rows(); ++r) {
    const int k = static_cast<int>(std::lround((t[r] - 0.1 + 2.5e-3) * 1e3));
    LONGS_EQUAL(0, k % 10);
    const TelemetrySnapshot want = sample(k);
    DOUBLES_EQUAL(want.row_t_s, t[r], 1e-9);
    DOUBLES_EQUAL(want.cx_v, rec.column("cx_v")[r], 0.5e-6);
    DOUBLES_EQUAL(want.cy_v, rec.column("cy_v")[r], 0.5e-6);
    DOUBLES_EQUAL(want.row_exc ? 1.0 : 0.0, rec.column("exc")[r], 0);
    DOUBLES_EQUAL(want.exc_on ? 1.0 : 0.0, rec.column("exc_cmd")[r], 0);
    DOUBLES_EQUAL(want.row_pump_v, rec.column("pump_v")[r], 0.5e-3);
    if (k == 0) continue;                                // before the bench's first frame
    DOUBLES_EQUAL(24.5, rec.column("temp_c")[r], 1e-9);  // the chamber's, not STATUS
    DOUBLES_EQUAL(table_rate_dps(k), rec.column("rate_dps")[r], 0.5e-6);
  }
  // AND the missing samples show as gaps, never filled in
  CHECK(rec.gaps().size() >= 2);
  // AND the compensation's health is the latest HRG_STATUS (10 Hz) and
  // HRG_EST_QUALITY (2 Hz: frames 492, 992, 1492, ...) before the row
  for (std::size_t r = 0; r < rec.rows(); ++r) {
    const int k = static_cast<int>(std::lround((t[r] - 0.1 + 2.5e-3) * 1e3));
    DOUBLES_EQUAL(0, rec.column("comp_valid")[r], 0);
    if (k >= 500 && k < 990) {
      DOUBLES_EQUAL(4, rec.column("comp_reasons")[r], 0);
      DOUBLES_EQUAL(0, rec.column("readout_damping_sigmas")[r], 0);
    } else if (k >= 1500) {
      DOUBLES_EQUAL(32 + 64, rec.column("comp_reasons")[r], 0);
      DOUBLES_EQUAL(12.5, rec.column("readout_damping_sigmas")[r], 0);
    }
  }
  std::remove(log.c_str());
  std::remove(o.out_path.c_str());
}

TEST(CanDecode, WithoutTheBenchTheTemperatureIsTheGyroStatusAndNoRateIsMadeUp) {
  const std::string log = write_log({}, false);
  const hrg::can::CanDecodeOptions o = options(log, "test_can_decode_nolab.csv");
  const hrg::can::CanDecodeSummary s = hrg::can::can_decode(o);
  CHECK_FALSE(s.has_lab_table);
  const hrg::recording::Recording rec = hrg::recording::read_recording(o.out_path);
  CHECK_FALSE(rec.has_column("rate_dps"));
  for (std::size_t r = 10; r < rec.rows(); ++r)
    DOUBLES_EQUAL(31.25, rec.column("temp_c")[r], 1e-9);
  std::remove(log.c_str());
  std::remove(o.out_path.c_str());
}

TEST(CanDecode, ALogWithoutTheReferenceIsRefusedUnlessItIsGiven) {
  std::set<std::pair<int, int>> drop;
  for (int i = 0; i < 2; ++i)
    drop.insert({static_cast<int>(Tm::reference), i});
  const std::string log = write_log(drop);
  hrg::can::CanDecodeOptions o = options(log, "test_can_decode_ref.csv");
  try {
    hrg::can::can_decode(o);
    FAIL("decoded without the reference");
  } catch (const std::runtime_error& e) {
    STRCMP_CONTAINS("HRG_REFERENCE", e.what());
  }
  o.f_ref_hz = 4999.87312;
  LONGS_EQUAL(200, hrg::can::can_decode(o).rows);
  std::remove(log.c_str());
  std::remove(o.out_path.c_str());
}

TEST(CanDecode, ALogWithoutTheAngularGainIsRefusedUnlessItIsGiven) {
  std::set<std::pair<int, int>> drop;
  for (int i = 0; i < 2; ++i)
    drop.insert({static_cast<int>(Tm::info), i});
  const std::string log = write_log(drop);
  hrg::can::CanDecodeOptions o;
  o.log_path = log;
  o.out_path = "test_can_decode_k.csv";
  o.dbc_path = std::string(std::getenv("HRG_SOURCE_DIR")) + "/firmware/can/hrg.dbc";
  try {
    hrg::can::can_decode(o);
    FAIL("decoded without K");
  } catch (const std::runtime_error& e) {
    STRCMP_CONTAINS("angular_gain", e.what());
  }
  o.angular_gain = 0.55;
  LONGS_EQUAL(200, hrg::can::can_decode(o).rows);
  std::remove(log.c_str());
  std::remove(o.out_path.c_str());
}

namespace {

double key(const hrg::recording::Recording& rec, const char* k) {
  const std::string v = rec.metadata_value(k);
  CHECK_TEXT(!v.empty(), k);
  return std::stod(v);
}

}  // namespace

TEST(CanDecode, TheLastCompleteSetOfTheFirmwareReadingsBecomesTheHeaderKeys) {
  // GIVEN two seconds of telemetry: HRG_CAL_READINGS sets start at frames
  // 86 and 1086 (10 Hz, 10 pages), the second's last page at frame 1986
  const std::string log = write_log({});
  const hrg::can::CanDecodeOptions o = options(log, "test_can_decode_readings.csv");
  // WHEN it is decoded
  const hrg::can::CanDecodeSummary s = hrg::can::can_decode(o);
  // THEN the keys are the second set's, held at its first page (frame 1086)
  LONGS_EQUAL(2, s.cal_readings_sets);
  const hrg::recording::Recording rec = hrg::recording::read_recording(o.out_path);
  const TelemetrySnapshot at = sample(1086);
  LONGS_EQUAL(11, static_cast<long>(key(rec, "pump_edge_edges")));
  DOUBLES_EQUAL(at.estimates.in_force_s, key(rec, "pump_edge_in_force_s"), 0.005);
  DOUBLES_EQUAL(at.estimates.feedthrough_residual_v_per_v.x_re, key(rec, "pump_edge_x_re_v_per_v"),
                1e-8);
  DOUBLES_EQUAL(-4e-4, key(rec, "pump_edge_y_im_v_per_v"), 1e-8);
  DOUBLES_EQUAL(2.7e-6, key(rec, "pump_edge_sigma_v_per_v"), 5e-10);
  DOUBLES_EQUAL(1.7e-6, key(rec, "pump_edge_scatter_v_per_v"), 5e-10);
  DOUBLES_EQUAL(1e-5, key(rec, "pump_edge_in_force_x_re_v_per_v"), 1e-8);
  DOUBLES_EQUAL(-2e-5, key(rec, "pump_edge_in_force_y_im_v_per_v"), 1e-8);
  DOUBLES_EQUAL(0.0039, key(rec, "damping_check_thermal_damping_per_c"), 5e-8);
  DOUBLES_EQUAL(1.5e-4, key(rec, "damping_check_thermal_damping_sigma_per_c"), 5e-9);
  // ... and the pickoff map's, each within half its resolution (4e-9, 2e-9)
  DOUBLES_EQUAL(at.estimates.pickoff_gain, key(rec, "self_cal_gain"), 2e-9);
  DOUBLES_EQUAL(6e-7, key(rec, "self_cal_gain_sigma"), 1e-9);
  DOUBLES_EQUAL(-0.0174578, key(rec, "self_cal_misalignment_rad"), 2e-9);
  DOUBLES_EQUAL(6.1e-6, key(rec, "self_cal_misalignment_sigma_rad"), 1e-9);
  DOUBLES_EQUAL(0.0174533, key(rec, "self_cal_phase_rad"), 2e-9);
  DOUBLES_EQUAL(1.3e-5, key(rec, "self_cal_phase_sigma_rad"), 1e-9);
  std::remove(log.c_str());
  std::remove(o.out_path.c_str());
}

TEST(CanDecode, ASetWithALostPageIsNotUsedAndWithoutACompleteSetNoKeyIsWritten) {
  const int rd = static_cast<int>(Tm::cal_readings);
  // GIVEN the second set's page 2 lost: the first set is the last complete one
  std::string log = write_log({{rd, 12}});
  hrg::can::CanDecodeOptions o = options(log, "test_can_decode_partial.csv");
  hrg::can::CanDecodeSummary s = hrg::can::can_decode(o);
  LONGS_EQUAL(1, s.cal_readings_sets);
  LONGS_EQUAL(1, s.cal_readings_dropped);
  hrg::recording::Recording rec = hrg::recording::read_recording(o.out_path);
  LONGS_EQUAL(1, static_cast<long>(key(rec, "pump_edge_edges")));  // held at frame 86
  // GIVEN a page of each set lost: no complete set, no key, nothing guessed
  log = write_log({{rd, 3}, {rd, 12}});
  s = hrg::can::can_decode(o);
  LONGS_EQUAL(0, s.cal_readings_sets);
  CHECK_FALSE(s.estimates.has_value());
  rec = hrg::recording::read_recording(o.out_path);
  for (const char* k : {"pump_edge_edges", "pump_edge_x_re_v_per_v", "pump_edge_in_force_s",
                        "damping_check_thermal_damping_per_c", "self_cal_gain"}) {
    CHECK_TEXT(rec.metadata_value(k).empty(), k);
  }
  std::remove(log.c_str());
  std::remove(o.out_path.c_str());
}

namespace {

// A log of one set of HRG_CAL_READINGS from `e`, pages 0 to `pages` - 1,
// beside rows (a recording has some), HRG_INFO and HRG_REFERENCE.
void write_one_set(const std::string& path, const FirmwareEstimates& e, uint8_t pages) {
  hrg::can::CandumpLogWriter w(path);
  const TelemetrySnapshot s = sample(0);
  w.write(encode_lab_table(0, 25, 0), kT0Ns);
  hrg::hal::CanFrame f;
  encode_telemetry(Tm::info, s, 0, f);
  w.write(f, kT0Ns + 1);
  encode_telemetry(Tm::reference, s, 0, f);
  w.write(f, kT0Ns + 2);
  for (uint8_t page = 0; page < pages; ++page) {
    encode_cal_readings(e, page, page, f);
    w.write(f, kT0Ns + 100'000'000ull * (page + 1));
    const TelemetrySnapshot row = sample(10 * page);
    for (const Tm m : {Tm::wave_x, Tm::wave_y, Tm::row}) {
      encode_telemetry(m, row, page, f);
      w.write(f, kT0Ns + 100'000'000ull * (page + 1) + 10);
    }
  }
}

}  // namespace

TEST(CanDecode, WithoutAFeedthroughThermalOrPickoffReadingTheirKeysAreLeftOut) {
  // GIVEN a set sent with no edge, no thermal reading and no pickoff map
  const std::string path = "test_can_decode_none.log";
  write_one_set(path, FirmwareEstimates{}, kCalReadingsPages);
  hrg::can::CanDecodeOptions o = options(path, "test_can_decode_none.csv");
  const hrg::can::CanDecodeSummary s = hrg::can::can_decode(o);
  // THEN the set is read, and says there is nothing to write
  LONGS_EQUAL(1, s.cal_readings_sets);
  const hrg::recording::Recording rec = hrg::recording::read_recording(o.out_path);
  CHECK_TRUE(rec.metadata_value("pump_edge_edges").empty());
  CHECK_TRUE(rec.metadata_value("damping_check_thermal_damping_per_c").empty());
  CHECK_TRUE(rec.metadata_value("self_cal_gain").empty());
  std::remove(path.c_str());
  std::remove(o.out_path.c_str());
}

namespace {

// The DBC of protocol 4: HRG_CAL_READINGS pages 0-6, no pickoff map.
std::string protocol_4_dbc() {
  const std::string path = "test_can_decode_protocol_4.dbc";
  std::ifstream in(std::string(std::getenv("HRG_SOURCE_DIR")) + "/firmware/can/hrg.dbc");
  std::ofstream out(path);
  for (std::string line; std::getline(in, line);) {
    if (line.find("self_cal_") != std::string::npos) continue;
    const auto page = line.find("SG_ page M : 0|4@1+ (1,0) [0|9]");
    if (page != std::string::npos) line.replace(line.find("[0|9]"), 5, "[0|6]");
    out << line << "\n";
  }
  return path;
}

}  // namespace

TEST(CanDecode, ALogOfProtocol4DecodesWithItsOwnDbcAndHasNoPickoffMap) {
  // GIVEN a log with one set of 7 pages, as protocol 4 sent it, and rows
  const std::string path = "test_can_decode_p4.log";
  write_one_set(path, sample(0).estimates, 7);
  // WHEN it is decoded with the DBC of its protocol
  hrg::can::CanDecodeOptions o = options(path, "test_can_decode_p4.csv");
  o.dbc_path = protocol_4_dbc();
  const hrg::can::CanDecodeSummary s = hrg::can::can_decode(o);
  // THEN the set of 7 is complete, its keys written, no self_cal_* key
  LONGS_EQUAL(1, s.cal_readings_sets);
  const hrg::recording::Recording rec = hrg::recording::read_recording(o.out_path);
  LONGS_EQUAL(1, static_cast<long>(key(rec, "pump_edge_edges")));
  CHECK_TRUE(rec.metadata_value("self_cal_gain").empty());
  // AND with this protocol's DBC the 7 pages are no set (nothing guessed)
  o.dbc_path = std::string(std::getenv("HRG_SOURCE_DIR")) + "/firmware/can/hrg.dbc";
  LONGS_EQUAL(0, hrg::can::can_decode(o).cal_readings_sets);
  std::remove(path.c_str());
  std::remove(o.out_path.c_str());
  std::remove("test_can_decode_protocol_4.dbc");
}

TEST(CanDecode, AReadingOutsideItsRangeIsRefusedNamingTheMessageTheSignalAndTheLine) {
  // GIVEN a log whose third line is HRG_CAL_READINGS with page 11 (the DBC's 0-9)
  const std::string path = "test_can_decode_bad.log";
  {
    hrg::can::CandumpLogWriter w(path);
    hrg::hal::CanFrame f;
    encode_cal_readings(FirmwareEstimates{}, 0, 0, f);
    w.write(f, kT0Ns);
    encode_cal_readings(FirmwareEstimates{}, 1, 1, f);
    w.write(f, kT0Ns + 1);
    f.data[0] = static_cast<uint8_t>((f.data[0] & 0xF0u) | 11u);
    w.write(f, kT0Ns + 2);
  }
  try {
    hrg::can::can_decode(options(path, "test_can_decode_bad.csv"));
    FAIL("decoded a page out of range");
  } catch (const std::runtime_error& e) {
    STRCMP_CONTAINS("test_can_decode_bad.log:3:", e.what());
    STRCMP_CONTAINS("HRG_CAL_READINGS signal 'page' = 11", e.what());
    STRCMP_CONTAINS("outside its range [0, 9]", e.what());
  }
  std::remove(path.c_str());
}
