// SPDX-License-Identifier: MIT
// candump -l logs: the writer produces what can-utils writes, and the reader
// reads it back exactly and names the line of anything malformed.
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "can/candump_log.hpp"

#include "support/cpputest.hpp"

using hrg::can::CandumpError;
using hrg::can::CandumpLogReader;
using hrg::can::CandumpLogWriter;
using hrg::can::LoggedFrame;
using hrg::hal::CanFrame;

TEST_GROUP(CandumpLog){};

TEST(CandumpLog, LinesAreFormattedAsCandumpWritesThem) {
  CanFrame f;
  f.id = 0x100;
  f.len = 8;
  for (uint8_t i = 0; i < 8; ++i)
    f.data[i] = static_cast<uint8_t>(i + 1);
  STRCMP_EQUAL("(0000000001.000500) can0 100#0102030405060708",
               hrg::can::format_candump_line(f, 1'000'500'999ull, "can0").c_str());
  f.extended = true;
  f.id = 0x1ABCDEF0;
  f.len = 0;
  STRCMP_EQUAL("(1700000000.123456) vcan0 1ABCDEF0#",
               hrg::can::format_candump_line(f, 1'700'000'000'123'456'000ull, "vcan0").c_str());
}

TEST(CandumpLog, RandomFramesRoundTripThroughWriterAndReader) {
  std::mt19937 rng(7);
  const std::string path = "test_candump_roundtrip.log";
  std::vector<CanFrame> frames;
  std::vector<uint64_t> times;
  {
    CandumpLogWriter w(path);
    uint64_t t = 0;
    for (int k = 0; k < 500; ++k) {
      CanFrame f;
      f.extended = (rng() % 4) == 0;
      f.id = static_cast<uint32_t>(rng() % (f.extended ? 0x20000000u : 0x800u));
      f.len = static_cast<uint8_t>(rng() % 9);
      for (uint8_t i = 0; i < f.len; ++i)
        f.data[i] = static_cast<uint8_t>(rng());
      t += 1000ull * (rng() % 5000);  // microsecond steps
      w.write(f, t);
      frames.push_back(f);
      times.push_back(t);
    }
    LONGS_EQUAL(500, w.frames_written());
  }
  std::ifstream in(path);
  CandumpLogReader r(in);
  LoggedFrame lf;
  std::size_t n = 0;
  while (r.next(lf)) {
    CHECK(n < frames.size());
    CHECK_EQUAL(times[n], lf.t_ns);
    STRCMP_EQUAL("can0", lf.interface.c_str());
    LONGS_EQUAL(frames[n].id, lf.frame.id);
    CHECK_EQUAL(frames[n].extended, lf.frame.extended);
    LONGS_EQUAL(frames[n].len, lf.frame.len);
    for (uint8_t i = 0; i < frames[n].len; ++i)
      LONGS_EQUAL(frames[n].data[i], lf.frame.data[i]);
    CHECK_FALSE(lf.error_frame);
    ++n;
  }
  LONGS_EQUAL(500, n);
  std::remove(path.c_str());
}

TEST(CandumpLog, ErrorAndRemoteFramesAreRecognised) {
  LoggedFrame lf;
  std::string err;
  CHECK(hrg::can::parse_candump_line("(12.5) can0 20000040#0000000000000000", lf, err));
  CHECK(lf.error_frame);
  LONGS_EQUAL(0x40, lf.frame.id);  // CAN_ERR_BUSOFF
  CHECK_EQUAL(12'500'000'000ull, lf.t_ns);
  CHECK(hrg::can::parse_candump_line("(1.000001) can1 123#R", lf, err));
  CHECK(lf.remote);
  CHECK(hrg::can::parse_candump_line("(1.000001) can1 123#11.22.33", lf, err));
  LONGS_EQUAL(3, lf.frame.len);
  LONGS_EQUAL(0x33, lf.frame.data[2]);
}

TEST(CandumpLog, MalformedLinesAreRefusedWithTheReason) {
  const char* bad[][2] = {
      {"(1.0) can0 100", "no '#'"},
      {"1.0 can0 100#00", "timestamp"},
      {"(1.0) can0 1000#00", "3 (standard) or 8"},
      {"(1.0) can0 800#00", "above 0x7FF"},
      {"(1.0) can0 10G#00", "not hexadecimal"},
      {"(1.0) can0 100#001", "odd number"},
      {"(1.0) can0 100#000102030405060708", "more than 8"},
      {"(1.0) can0 100##100", "CAN FD"},
      {"(1.0) can0 40000100#00", "flag bits"},
      {"(1.x) can0 100#00", "fraction"},
      {"(1.0)", "expected"},
      {"(1.0) can\x01 100#00", "non-printable"},
      {"(1.0) an-interface-name-too-long 100#00", "longer than 15"},
      {"(18446744073.0) can0 100#00", "beyond"},
  };
  for (const auto& b : bad) {
    LoggedFrame lf;
    std::string err;
    CHECK_FALSE_TEXT(hrg::can::parse_candump_line(b[0], lf, err), b[0]);
    STRCMP_CONTAINS(b[1], err.c_str());
  }
}

TEST(CandumpLog, TheReaderNamesTheLineOfAMalformedRecord) {
  std::istringstream in("(1.000000) can0 100#00\n\n(1.000100) can0 101#zz\n");
  CandumpLogReader r(in);
  LoggedFrame lf;
  CHECK(r.next(lf));
  try {
    r.next(lf);
    FAIL("malformed line accepted");
  } catch (const CandumpError& e) {
    LONGS_EQUAL(3, e.line());
    STRCMP_CONTAINS("line 3", e.what());
  }
}
