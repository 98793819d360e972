// SPDX-License-Identifier: MIT
// The Linux board's temperature input: a file of millidegrees Celsius (IIO
// in_temp*_input, hwmon temp*_input), here a temporary file standing in for
// the sysfs attribute.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "hal/linux/file_temperature.hpp"

#include "support/cpputest.hpp"

using namespace hrg::hal;
using namespace hrg::hal::linux_board;

namespace {

// A temporary file whose content the test rewrites (as the kernel would
// present a new conversion).
struct TempFile {
  std::string path;
  TempFile() {
    char name[] = "/tmp/hrg_temp_input_XXXXXX";
    const int fd = mkstemp(name);
    CHECK(fd >= 0);
    ::close(fd);
    path = name;
  }
  ~TempFile() { std::remove(path.c_str()); }
  void write(const char* content) const {
    FILE* f = std::fopen(path.c_str(), "w");
    CHECK(f != nullptr);
    std::fputs(content, f);
    std::fclose(f);
  }
};

}  // namespace

TEST_GROUP(FileTemperature){};

TEST(FileTemperature, MillidegreesAsTheKernelWritesThemAreDegreesC) {
  double t = 0.0;
  CHECK(parse_millidegrees("23456\n", 6, t));
  DOUBLES_EQUAL(23.456, t, 1e-12);
  CHECK(parse_millidegrees("-1500", 5, t));
  DOUBLES_EQUAL(-1.5, t, 1e-12);
  CHECK(parse_millidegrees("+7 \n", 4, t));
  DOUBLES_EQUAL(0.007, t, 1e-15);
  CHECK_FALSE(parse_millidegrees("", 0, t));
  CHECK_FALSE(parse_millidegrees("23.4\n", 5, t));  // degrees, not millidegrees
  CHECK_FALSE(parse_millidegrees("abc", 3, t));
  CHECK_FALSE(parse_millidegrees("-", 1, t));
  CHECK_FALSE(parse_millidegrees("1234567890", 10, t));  // beyond 1e6 degC
}

TEST(FileTemperature, EveryReadTakesTheFileAfresh) {
  TempFile f;
  f.write("25000\n");
  FileTemperatureSensor s;
  CHECK(s.open(f.path.c_str()) == Status::ok);
  STRCMP_EQUAL("", s.error());
  double t = 0.0;
  CHECK(s.read(t) == Status::ok);
  DOUBLES_EQUAL(25.0, t, 0.0);
  f.write("26125\n");
  CHECK(s.read(t) == Status::ok);
  DOUBLES_EQUAL(26.125, t, 1e-12);
}

TEST(FileTemperature, BadContentIsRefusedNamingThePathAndWhatWasThere) {
  TempFile f;
  f.write("hot\n");
  FileTemperatureSensor s;
  CHECK(s.open(f.path.c_str()) == Status::io_error);
  CHECK_FALSE(s.is_open());
  const std::string e = s.error();
  CHECK(e.find(f.path) != std::string::npos);
  CHECK(e.find("'hot'") != std::string::npos);
  CHECK(e.find("millidegrees") != std::string::npos);
  double t = 3.0;
  CHECK(s.read(t) == Status::closed);
  DOUBLES_EQUAL(3.0, t, 0.0);
}

TEST(FileTemperature, ContentGoingBadAfterOpenIsAnIoErrorAndKeepsTheValue) {
  TempFile f;
  f.write("24000\n");
  FileTemperatureSensor s;
  CHECK(s.open(f.path.c_str()) == Status::ok);
  f.write("");
  double t = 24.0;
  CHECK(s.read(t) == Status::io_error);
  DOUBLES_EQUAL(24.0, t, 0.0);
  CHECK(std::string(s.error()).find(f.path) != std::string::npos);
  f.write("24500");
  CHECK(s.read(t) == Status::ok);
  DOUBLES_EQUAL(24.5, t, 1e-12);
  STRCMP_EQUAL("", s.error());
}

TEST(FileTemperature, AMissingFileIsClosedNamingThePath) {
  FileTemperatureSensor s;
  CHECK(s.open("/nonexistent/hwmon0/temp1_input") == Status::closed);
  CHECK(std::string(s.error()).find("/nonexistent/hwmon0/temp1_input") != std::string::npos);
  double t = 0.0;
  CHECK(s.read(t) == Status::closed);
}
