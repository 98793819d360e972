// SPDX-License-Identifier: MIT
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "recording/recording.hpp"
#include "recording/recording_writer.hpp"

#include "support/cpputest.hpp"

namespace fs = std::filesystem;
using hrg::recording::parse_recording;
using hrg::recording::Recording;
using hrg::recording::RecordingError;

namespace {

const char* kGood =
    "# hrg-recording v1\n"
    "# f_ref_hz=4999.8731\n"
    "# angular_gain=0.554\n"
    "# source=unit test\n"
    "t_s,cx_v,sx_v,cy_v,sy_v,exc,pump_v,my_extra\n"
    "0.005,1.5,0.001,0.002,-0.0001,1,9.5,7\n"
    "0.010,1.49,0.002,0.003,-0.0002,0,0,8\n"
    "0.015,1.48,0.003,0.004,-0.0003,0,0,9\n";

// Runs the parser on `text` and returns the error it raises (line, column).
RecordingError error_of(const std::string& text) {
  try {
    parse_recording(text, "bad.csv");
  } catch (const RecordingError& e) {
    return e;
  }
  FAIL("parser accepted a malformed recording");
  return RecordingError("", 0, "", "");
}

std::string replace_line(std::string text, int line_index, const std::string& line) {
  std::size_t pos = 0;
  for (int i = 0; i < line_index; ++i)
    pos = text.find('\n', pos) + 1;
  const std::size_t end = text.find('\n', pos);
  return text.replace(pos, end - pos, line);
}

fs::path temp_path(const std::string& name) {
  return fs::temp_directory_path() / ("hrg_test_recording_" + name);
}

}  // namespace

TEST_GROUP(RecordingReader){};

TEST(RecordingReader, ReadsMetadataColumnsAndKeepsUnknownColumns) {
  const Recording r = parse_recording(kGood, "good.csv");
  DOUBLES_EQUAL(4999.8731, r.f_ref_hz(), 1e-12);
  DOUBLES_EQUAL(0.554, r.angular_gain(), 1e-15);
  STRCMP_EQUAL("unit test", r.metadata_value("source").c_str());
  LONGS_EQUAL(3, r.rows());
  CHECK(r.has_column("my_extra"));
  DOUBLES_EQUAL(9.0, r.column("my_extra")[2], 0.0);
  DOUBLES_EQUAL(-0.0003, r.column("sy_v")[2], 0.0);
  DOUBLES_EQUAL(0.0, r.column("exc")[1], 0.0);
  LONGS_EQUAL(0, r.gaps().size());
}

TEST(RecordingReader, NonNumericCellNamesLineAndColumn) {
  const auto e = error_of(replace_line(kGood, 6, "0.010,1.49,abc,0.003,-0.0002,0,0,8"));
  LONGS_EQUAL(7, e.line());
  STRCMP_EQUAL("sx_v", e.column().c_str());
  CHECK(std::string(e.what()).find("line 7") != std::string::npos);
  CHECK(std::string(e.what()).find("'sx_v'") != std::string::npos);
}

TEST(RecordingReader, NanCellIsRejectedWithItsPlace) {
  const auto e = error_of(replace_line(kGood, 7, "0.015,1.48,0.003,nan,-0.0003,0,0,9"));
  LONGS_EQUAL(8, e.line());
  STRCMP_EQUAL("cy_v", e.column().c_str());
  CHECK(std::string(e.what()).find("NaN") != std::string::npos);
}

TEST(RecordingReader, TimeGoingBackwardsIsRejected) {
  const auto e = error_of(replace_line(kGood, 7, "0.0099,1.48,0.003,0.004,-0.0003,0,0,9"));
  LONGS_EQUAL(8, e.line());
  STRCMP_EQUAL("t_s", e.column().c_str());
}

TEST(RecordingReader, RepeatedTimeIsRejected) {
  const auto e = error_of(replace_line(kGood, 7, "0.010,1.48,0.003,0.004,-0.0003,0,0,9"));
  LONGS_EQUAL(8, e.line());
}

TEST(RecordingReader, MissingRequiredColumnNamesIt) {
  const auto e = error_of(replace_line(kGood, 4, "t_s,cx_v,sx_v,cy_v,exc,pump_v,my_extra"));
  LONGS_EQUAL(5, e.line());
  STRCMP_EQUAL("sy_v", e.column().c_str());
}

TEST(RecordingReader, MissingRequiredMetadataNamesIt) {
  const auto e = error_of(replace_line(kGood, 2, "# gain_note=none"));
  CHECK(std::string(e.what()).find("angular_gain") != std::string::npos);
}

TEST(RecordingReader, NonNumericMetadataIsRejected) {
  const auto e = error_of(replace_line(kGood, 1, "# f_ref_hz=five kHz"));
  LONGS_EQUAL(2, e.line());
}

// "+-x" carries two signs: from_chars would take the '-' after a stripped
// '+', so the reader checks for it (a numeric key once reached std::stod and
// threw past the reader's own error).
TEST(RecordingReader, TwoSignsInANumericMetadataValueAreRejectedNamingTheKey) {
  const auto e = error_of(replace_line(kGood, 2, "# angular_gain=+-0.554"));
  LONGS_EQUAL(3, e.line());
  CHECK(std::string(e.what()).find("angular_gain") != std::string::npos);
}

TEST(RecordingReader, TwoSignsInACellAreRejectedWithTheirPlace) {
  const auto e = error_of(replace_line(kGood, 6, "0.010,1.49,+-0.002,0.003,-0.0002,0,0,8"));
  LONGS_EQUAL(7, e.line());
  STRCMP_EQUAL("sx_v", e.column().c_str());
}

TEST(RecordingReader, ASetNumericKeyThatIsNotANumberNamesIt) {
  Recording r = parse_recording(kGood, "good.csv");
  try {
    r.set_metadata("f_ref_hz", "+-5000");
    FAIL("set_metadata accepted two signs");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()).find("f_ref_hz") != std::string::npos);
  }
  DOUBLES_EQUAL(4999.8731, r.f_ref_hz(), 0.0);
}

TEST(RecordingReader, ShortRowIsRejected) {
  const auto e = error_of(replace_line(kGood, 5, "0.005,1.5,0.001"));
  LONGS_EQUAL(6, e.line());
}

TEST(RecordingReader, ExcOtherThanZeroOrOneIsRejected) {
  const auto e = error_of(replace_line(kGood, 5, "0.005,1.5,0.001,0.002,-0.0001,0.5,9.5,7"));
  STRCMP_EQUAL("exc", e.column().c_str());
  LONGS_EQUAL(6, e.line());
}

TEST(RecordingReader, WrongVersionLineIsRejected) {
  const auto e = error_of(replace_line(kGood, 0, "# hrg-recording v2"));
  LONGS_EQUAL(1, e.line());
}

TEST(RecordingReader, GapIsReportedNotFilled) {
  std::string text =
      "# hrg-recording v1\n# f_ref_hz=5000\n# angular_gain=0.554\n"
      "t_s,cx_v,sx_v,cy_v,sy_v,exc\n";
  // 0.005 s steps with samples 10..13 missing: 5 missing steps between 0.045 and 0.07.
  for (int k = 1; k <= 20; ++k) {
    if (k >= 10 && k <= 13) continue;
    char line[128];
    std::snprintf(line, sizeof line, "%.3f,1,0,0,0,0\n", 0.005 * k);
    text += line;
  }
  const Recording r = parse_recording(text, "gap.csv");
  LONGS_EQUAL(16, r.rows());
  LONGS_EQUAL(1, r.gaps().size());
  LONGS_EQUAL(9, r.gaps()[0].row);
  LONGS_EQUAL(4 + 10, r.gaps()[0].line);
  DOUBLES_EQUAL(0.045, r.gaps()[0].t_before_s, 1e-12);
  DOUBLES_EQUAL(0.070, r.gaps()[0].t_after_s, 1e-12);
  DOUBLES_EQUAL(4.0, r.gaps()[0].missing_samples, 1e-9);
}

TEST_GROUP(RecordingWriter){};

TEST(RecordingWriter, GzipRoundTripIsExact) {
  Recording r({"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc", "temp_c"}, 5003.262, 0.554);
  r.set_metadata("source", "round trip");
  for (int k = 0; k < 500; ++k) {
    const double t = 0.005 * (k + 1);
    r.append_row({t, std::cos(t) * 1.23456789, std::sin(t) / 3.0, 1e-7 * k, -2.5e-9 * k,
                  k % 7 == 0 ? 1.0 : 0.0, 25.0 + 1e-3 * k});
  }
  const fs::path p = temp_path("rt.csv.gz");
  hrg::recording::write_recording(p, r);
  const Recording back = hrg::recording::read_recording(p);
  fs::remove(p);
  LONGS_EQUAL(r.rows(), back.rows());
  DOUBLES_EQUAL(5003.262, back.f_ref_hz(), 0.0);
  STRCMP_EQUAL("round trip", back.metadata_value("source").c_str());
  for (const auto& name : r.column_names()) {
    for (std::size_t i = 0; i < r.rows(); ++i) {
      DOUBLES_EQUAL(r.column(name)[i], back.column(name)[i], 0.0);
    }
  }
}

TEST(RecordingWriter, StreamingWriterRefusesTimeGoingBackwards) {
  const fs::path p = temp_path("stream.csv");
  {
    hrg::recording::RecordingWriter w(p, {"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc"}, 5000.0,
                                      0.554);
    const std::vector<double> a{0.01, 1, 0, 0, 0, 1};
    const std::vector<double> b{0.005, 1, 0, 0, 0, 1};
    w.write_row(a);
    CHECK_THROWS(std::invalid_argument, w.write_row(b));
    const std::vector<double> c{0.02, 1, NAN, 0, 0, 1};
    CHECK_THROWS(std::invalid_argument, w.write_row(c));
    LONGS_EQUAL(1, w.rows_written());
  }
  const Recording back = hrg::recording::read_recording(p);
  fs::remove(p);
  LONGS_EQUAL(1, back.rows());
}

TEST(RecordingWriter, MissingFileGivesAClearError) {
  try {
    hrg::recording::read_recording("/nonexistent/dir/none.csv");
    FAIL("no error");
  } catch (const RecordingError& e) {
    CHECK(std::string(e.what()).find("none.csv") != std::string::npos);
  }
}

TEST_GROUP(SharedExamples){};

TEST(SharedExamples, LabRingDownCampaignReadsWhole) {
  const char* src = std::getenv("HRG_SOURCE_DIR");
  CHECK_TRUE(src != nullptr);
  const fs::path p = fs::path(src) / ".." / "shared" / "examples" / "ringdown-baseline.csv.gz";
  Recording r;
  try {
    r = hrg::recording::read_recording(p);
  } catch (const RecordingError& e) {
    FAIL(e.what());
  }
  // 119925 lines = version + 3 metadata + header + rows.
  LONGS_EQUAL(119925 - 5, r.rows());
  DOUBLES_EQUAL(5003.262, r.f_ref_hz(), 1e-9);
  DOUBLES_EQUAL(0.005, r.typical_step_s(), 1e-9);
  CHECK(r.has_column("rate_dps"));
}

TEST_GROUP(RecordingGzip){
    // A 500-row recording written gzip-compressed; its bytes.
    std::string gz_bytes(){
        Recording r({"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc"}, 5000.0, 0.554);
for (int k = 0; k < 500; ++k) {
  const double t = 0.002 * (k + 1);
  r.append_row({t, std::cos(t), std::sin(3 * t) / 7.0, 1e-7 * k, -2.5e-9 * k, 0.0});
}
const fs::path p = temp_path("gz_src.csv.gz");
hrg::recording::write_recording(p, r);
std::ifstream in(p, std::ios::binary);
std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
fs::remove(p);
return bytes;
}
// read_recording's error for a file holding `bytes`, named `name`.
std::string read_error(const std::string& bytes, const std::string& name) {
  const fs::path p = temp_path(name);
  std::ofstream(p, std::ios::binary) << bytes;
  std::string what;
  try {
    hrg::recording::read_recording(p);
    what = "no error";
  } catch (const RecordingError& e) {
    LONGS_EQUAL(0, e.line());  // a stream error, not a line of the text
    what = e.what();
  }
  fs::remove(p);
  return what;
}
static bool has(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}
}
;

TEST(RecordingGzip, TruncatedStreamIsReportedAsTruncatedNamingTheFile) {
  const std::string gz = gz_bytes();
  // Inside the header, inside the deflate data, and short of the 8-byte
  // trailer (CRC-32 and length) by one byte.
  for (const std::size_t keep : {std::size_t{5}, gz.size() / 2, gz.size() - 1}) {
    const std::string what = read_error(gz.substr(0, keep), "cut.csv.gz");
    CHECK_TEXT(has(what, "truncated gzip stream"), what.c_str());
    CHECK_TEXT(has(what, "cut.csv.gz"), what.c_str());
    CHECK_TEXT(has(what, "after " + std::to_string(keep) + " compressed bytes"), what.c_str());
    CHECK_TEXT(!has(what, "first line"), what.c_str());
  }
}

TEST(RecordingGzip, CorruptDataIsReportedAsCorruptNamingTheFile) {
  std::string gz = gz_bytes();
  gz[gz.size() - 6] ^= 0x5a;  // inside the CRC-32 of the trailer
  std::string what = read_error(gz, "crc.csv.gz");
  CHECK_TEXT(has(what, "corrupt gzip data"), what.c_str());
  CHECK_TEXT(has(what, "crc.csv.gz"), what.c_str());
  CHECK_TEXT(has(what, "incorrect data check"), what.c_str());
  gz = gz_bytes();
  gz[3] = static_cast<char>(0xe0);  // reserved header flag bits
  what = read_error(gz, "flags.csv.gz");
  CHECK_TEXT(has(what, "corrupt gzip data at compressed byte"), what.c_str());
  CHECK_TEXT(has(what, "flags.csv.gz"), what.c_str());
}

TEST(RecordingGzip, ConcatenatedMembersReadAsOneText) {
  const std::string gz = gz_bytes();
  const std::string text = hrg::recording::gunzip(gz, "one");
  CHECK(text.rfind("# hrg-recording v1\n", 0) == 0);
  // Two members in a row (as `cat a.gz b.gz` makes) are one text.
  STRCMP_EQUAL((text + text).c_str(), hrg::recording::gunzip(gz + gz, "two").c_str());
  // Bytes after the last member that start no member are corrupt, not ignored.
  const std::string what = read_error(gz + "xyz", "tail.csv.gz");
  CHECK_TEXT(has(what, "corrupt gzip data"), what.c_str());
}
