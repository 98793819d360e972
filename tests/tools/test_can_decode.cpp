// SPDX-License-Identifier: MIT
// `hrg can-decode`: a candump log of the firmware's telemetry, with frames
// removed as a bus would lose them, becomes an hrg-recording v1 whose rows are
// the transmitted samples and whose metadata counts exactly the removed frames.
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <string>

#include "can/can_decode.hpp"
#include "can/candump_log.hpp"
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
  s.pump_v = 9.5;
  s.temp_c = 31.25;
  s.pll_freq_hz = 4999.87310 + 1e-4 * k;
  s.angular_gain = 0.554;
  s.mode = hrg::fw::Mode::operate;
  return s;
}

// Two seconds of default-rate telemetry; drops the frames for which `drop`
// says so (message index, occurrence).
std::string write_log(const std::set<std::pair<int, int>>& drop) {
  const std::string path = "test_can_decode.log";
  hrg::can::CandumpLogWriter w(path);
  TelemetryEncoder enc(TelemetryConfig::defaults(), 1000);
  std::array<hrg::hal::CanFrame, kTelemetryCount> out;
  std::array<int, kTelemetryCount> seen{};
  for (int k = 0; k < 2000; ++k) {
    const std::size_t n = enc.tick(sample(k), out);
    for (std::size_t j = 0; j < n; ++j) {
      const auto i = static_cast<int>(find_message(out[j].id) - kTelemetry.data());
      if (drop.count({i, seen[i]++}) == 0) w.write(out[j], kT0Ns + 1'000'000ull * k + 10 * j);
    }
  }
  return path;
}

}  // namespace

TEST_GROUP(CanDecode){};

TEST(CanDecode, RowsAreTheTransmittedSamplesAndLossesAreCountedPerMessage) {
  // GIVEN a log that lost WAVE_X #100, WAVE_Y #300, #301, #302 and LOOPS #50, #51
  const int wx = static_cast<int>(Tm::wave_x);
  const int wy = static_cast<int>(Tm::wave_y);
  const int lp = static_cast<int>(Tm::loops);
  const std::string log =
      write_log({{wx, 100}, {wy, 300}, {wy, 301}, {wy, 302}, {lp, 50}, {lp, 51}});
  hrg::can::CanDecodeOptions o;
  o.log_path = log;
  o.out_path = "test_can_decode.csv";
  o.dbc_path = std::string(std::getenv("HRG_SOURCE_DIR")) + "/firmware/can/hrg.dbc";
  // WHEN it is decoded
  const hrg::can::CanDecodeSummary s = hrg::can::can_decode(o);
  // THEN 1000 samples less the 4 incomplete ones are rows
  LONGS_EQUAL(996, s.rows);
  LONGS_EQUAL(1, s.messages.at("HRG_WAVE_X").lost);
  LONGS_EQUAL(3, s.messages.at("HRG_WAVE_Y").lost);
  LONGS_EQUAL(2, s.messages.at("HRG_LOOPS").lost);
  LONGS_EQUAL(0, s.messages.at("HRG_ANGLE").lost);
  DOUBLES_EQUAL(0.554, s.angular_gain, 1e-12);
  // The first HRG_LOOPS goes out at frame 7 (staggered by its table index 3).
  DOUBLES_EQUAL(4999.87310 + 7e-4, s.f_ref_hz, 0.5e-5);
  const hrg::recording::Recording rec = hrg::recording::read_recording(o.out_path);
  LONGS_EQUAL(996, rec.rows());
  STRCMP_EQUAL("1 of 1000", rec.metadata_value("can_lost_HRG_WAVE_X").c_str());
  STRCMP_EQUAL("3 of 1000", rec.metadata_value("can_lost_HRG_WAVE_Y").c_str());
  // AND each row holds the sample of its frame: WAVE_X goes out on even frames
  // (k = 2 m), so row time t_s = 2 m ms and cx = 1.2 cos(0.3 t).
  const auto& t = rec.column("t_s");
  const auto& cx = rec.column("cx_v");
  const auto& cy = rec.column("cy_v");
  const auto& exc = rec.column("exc");
  const auto& f_ref = rec.column("f_ref_hz");
  for (std::size_t r = 0; r < rec.rows(); ++r) {
    const int k = static_cast<int>(std::lround(t[r] * 1e3));
    DOUBLES_EQUAL(1e-3 * k, t[r], 1e-9);
    const TelemetrySnapshot want = sample(k);
    DOUBLES_EQUAL(want.cx_v, cx[r], 0.5e-6);
    DOUBLES_EQUAL(want.cy_v, cy[r], 0.5e-6);
    DOUBLES_EQUAL(want.exc_on ? 1.0 : 0.0, exc[r], 0);
    CHECK(std::fabs(f_ref[r] - want.pll_freq_hz) < 0.011);  // latest LOOPS, <= 10 ms old
  }
  // AND the missing samples show as gaps, never filled in
  CHECK(rec.gaps().size() >= 2);
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
  LONGS_EQUAL(1000, hrg::can::can_decode(o).rows);
  std::remove(log.c_str());
  std::remove(o.out_path.c_str());
}
