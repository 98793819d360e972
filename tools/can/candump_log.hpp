// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <cstdio>
#include <istream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "hal/can.hpp"

namespace hrg::can {

// One line of a can-utils `candump -l` log:
//   (1700000000.123456) can0 123#DEADBEEF
// Standard identifiers are written with 3 hex digits, extended ones with 8;
// error frames carry CAN_ERR_FLAG (0x20000000) in an 8-digit identifier and
// remote frames end in "#R". canplayer and python-can read this format.
struct LoggedFrame {
  uint64_t t_ns = 0;      // timestamp of the frame (log time base)
  std::string interface;  // e.g. "can0"
  hal::CanFrame frame;    // identifier without the flag bits
  bool error_frame = false;
  bool remote = false;
};

// Malformed log input; `line` is 1-based.
class CandumpError : public std::runtime_error {
 public:
  CandumpError(std::size_t line, const std::string& what);
  std::size_t line() const { return line_; }

 private:
  std::size_t line_;
};

// Formats one frame as a candump -l line (without the newline).
std::string format_candump_line(const hal::CanFrame& frame, uint64_t t_ns,
                                std::string_view interface);

// Parses one line. Returns false and sets `error` (what is wrong and where in
// the line) when the line is not a classic CAN candump -l record.
bool parse_candump_line(std::string_view line, LoggedFrame& out, std::string& error);

// Writes frames with their timestamps as a candump -l log. Timestamps are
// nanoseconds on any monotonic base (the simulator uses simulated time from 0);
// they are written with microsecond resolution as candump does.
class CandumpLogWriter {
 public:
  // Opens (truncates) `path`; throws std::runtime_error naming the path on failure.
  explicit CandumpLogWriter(const std::string& path, std::string interface = "can0");
  ~CandumpLogWriter();
  CandumpLogWriter(const CandumpLogWriter&) = delete;
  CandumpLogWriter& operator=(const CandumpLogWriter&) = delete;

  // Appends one frame. Throws std::runtime_error when the write fails.
  void write(const hal::CanFrame& frame, uint64_t t_ns);
  // Flushes buffered lines to the file.
  void flush();
  uint64_t frames_written() const { return frames_written_; }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::string interface_;
  uint64_t frames_written_ = 0;
};

// Reads a candump -l log line by line. Blank lines are skipped; a malformed
// line throws CandumpError with its line number.
class CandumpLogReader {
 public:
  explicit CandumpLogReader(std::istream& in) : in_(in) {}
  // Returns false at the end of the input.
  bool next(LoggedFrame& out);
  std::size_t line_number() const { return line_; }

 private:
  std::istream& in_;
  std::size_t line_ = 0;
  std::string buf_;
};

}  // namespace hrg::can
