// SPDX-License-Identifier: MIT
#include "can/candump_log.hpp"

#include <cerrno>
#include <cinttypes>
#include <cstring>

namespace hrg::can {

namespace {

constexpr uint32_t kErrFlag = 0x20000000u;  // CAN_ERR_FLAG in linux/can.h
constexpr uint32_t kMaxExtendedId = 0x1FFFFFFFu;
constexpr uint32_t kMaxStandardId = 0x7FFu;

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool parse_timestamp(std::string_view s, uint64_t& t_ns, std::string& error) {
  // "(seconds.fraction)"; candump writes 6 fraction digits, accept 1..9.
  if (s.size() < 3 || s.front() != '(' || s.back() != ')') {
    error = "timestamp must look like (seconds.microseconds)";
    return false;
  }
  s = s.substr(1, s.size() - 2);
  const auto dot = s.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 >= s.size() || dot > 12 ||
      s.size() - dot - 1 > 9) {
    error = "timestamp needs 1-12 digits of seconds, a dot and 1-9 fraction digits";
    return false;
  }
  uint64_t sec = 0;
  for (std::size_t i = 0; i < dot; ++i) {
    if (s[i] < '0' || s[i] > '9') {
      error = "timestamp seconds are not decimal digits";
      return false;
    }
    sec = sec * 10 + static_cast<uint64_t>(s[i] - '0');
  }
  uint64_t frac_ns = 0;
  uint64_t scale = 100'000'000;
  for (std::size_t i = dot + 1; i < s.size(); ++i) {
    if (s[i] < '0' || s[i] > '9') {
      error = "timestamp fraction is not decimal digits";
      return false;
    }
    frac_ns += static_cast<uint64_t>(s[i] - '0') * scale;
    scale /= 10;
  }
  // 18446744072 s is the last whole second representable in uint64 nanoseconds.
  if (sec >= 18'446'744'073ull) {
    error = "timestamp beyond year 2554";
    return false;
  }
  t_ns = sec * 1'000'000'000ull + frac_ns;
  return true;
}

// The identifier before '#': 3 hex digits (standard) or 8 (extended, with
// CAN_ERR_FLAG marking an error frame). Fills id, extended and error_frame.
bool parse_identifier(std::string_view id_text, LoggedFrame& out, std::string& error) {
  if (id_text.size() != 3 && id_text.size() != 8) {
    error = "identifier must have 3 (standard) or 8 (extended) hex digits";
    return false;
  }
  uint32_t id = 0;
  for (char c : id_text) {
    const int v = hex_value(c);
    if (v < 0) {
      error = "identifier is not hexadecimal";
      return false;
    }
    id = (id << 4) | static_cast<uint32_t>(v);
  }
  if (id_text.size() == 8) {
    out.error_frame = (id & kErrFlag) != 0;
    if ((id & ~(kErrFlag | kMaxExtendedId)) != 0) {
      error = "identifier has flag bits other than CAN_ERR_FLAG";
      return false;
    }
    out.frame.extended = !out.error_frame;
    id &= kMaxExtendedId;
  } else if (id > kMaxStandardId) {
    error = "standard identifier above 0x7FF";
    return false;
  }
  out.frame.id = id;
  return true;
}

// After "R": nothing, or the requested length 0-8.
bool parse_remote(std::string_view data, LoggedFrame& out, std::string& error) {
  out.remote = true;
  if (data.size() == 1 && data[0] >= '0' && data[0] <= '8') {
    out.frame.len = static_cast<uint8_t>(data[0] - '0');
    return true;
  }
  if (!data.empty()) {
    error = "remote frame has trailing characters";
    return false;
  }
  return true;
}

// Up to 8 bytes as hex pairs. candump -l writes them without separators;
// cansend-style dots are accepted.
bool parse_data(std::string_view data, LoggedFrame& out, std::string& error) {
  std::size_t n = 0;
  std::size_t i = 0;
  while (i < data.size()) {
    if (data[i] == '.') {
      ++i;
      continue;
    }
    if (i + 1 >= data.size()) {
      error = "data has an odd number of hex digits";
      return false;
    }
    const int hi = hex_value(data[i]);
    const int lo = hex_value(data[i + 1]);
    if (hi < 0 || lo < 0) {
      error = "data is not hexadecimal";
      return false;
    }
    if (n >= out.frame.data.size()) {
      error = "more than 8 data bytes in a classic CAN frame";
      return false;
    }
    out.frame.data[n++] = static_cast<uint8_t>((hi << 4) | lo);
    i += 2;
  }
  out.frame.len = static_cast<uint8_t>(n);
  return true;
}

bool parse_frame(std::string_view s, LoggedFrame& out, std::string& error) {
  const auto hash = s.find('#');
  if (hash == std::string_view::npos) {
    error = "frame has no '#' between identifier and data";
    return false;
  }
  out.error_frame = false;
  out.remote = false;
  out.frame = hal::CanFrame{};
  if (!parse_identifier(s.substr(0, hash), out, error)) return false;
  std::string_view data = s.substr(hash + 1);
  if (!data.empty() && data.front() == '#') {
    error = "CAN FD frames (##) are not classic CAN";
    return false;
  }
  if (!data.empty() && (data.front() == 'R' || data.front() == 'r')) {
    return parse_remote(data.substr(1), out, error);
  }
  return parse_data(data, out, error);
}

}  // namespace

CandumpError::CandumpError(std::size_t line, const std::string& what)
    : std::runtime_error("candump log line " + std::to_string(line) + ": " + what), line_(line) {}

std::string format_candump_line(const hal::CanFrame& frame, uint64_t t_ns,
                                std::string_view interface) {
  char buf[96];
  const uint64_t sec = t_ns / 1'000'000'000ull;
  const uint64_t usec = (t_ns % 1'000'000'000ull) / 1000u;
  int n = std::snprintf(buf, sizeof buf, "(%010" PRIu64 ".%06" PRIu64 ") %.*s ", sec, usec,
                        static_cast<int>(interface.size()), interface.data());
  std::string line(buf, static_cast<std::size_t>(n));
  if (frame.extended) {
    n = std::snprintf(buf, sizeof buf, "%08" PRIX32 "#", frame.id & kMaxExtendedId);
  } else {
    n = std::snprintf(buf, sizeof buf, "%03" PRIX32 "#", frame.id & kMaxStandardId);
  }
  line.append(buf, static_cast<std::size_t>(n));
  const std::size_t len = frame.len > 8 ? 8 : frame.len;
  for (std::size_t i = 0; i < len; ++i) {
    std::snprintf(buf, sizeof buf, "%02X", frame.data[i]);
    line.append(buf, 2);
  }
  return line;
}

bool parse_candump_line(std::string_view line, LoggedFrame& out, std::string& error) {
  while (!line.empty() && (line.back() == '\r' || line.back() == '\n' || line.back() == ' '))
    line.remove_suffix(1);
  const auto sp1 = line.find(' ');
  if (sp1 == std::string_view::npos) {
    error = "expected '(time) interface id#data'";
    return false;
  }
  const auto sp2 = line.find(' ', sp1 + 1);
  if (sp2 == std::string_view::npos || sp2 == sp1 + 1) {
    error = "expected an interface name after the timestamp";
    return false;
  }
  if (!parse_timestamp(line.substr(0, sp1), out.t_ns, error)) return false;
  const std::string_view iface = line.substr(sp1 + 1, sp2 - sp1 - 1);
  // Linux interface names: at most 15 printable characters (IFNAMSIZ - 1).
  if (iface.size() > 15) {
    error = "interface name longer than 15 characters";
    return false;
  }
  for (char c : iface) {
    if (c <= ' ' || c > '~') {
      error = "interface name has a non-printable character";
      return false;
    }
  }
  out.interface = std::string(iface);
  std::string_view rest = line.substr(sp2 + 1);
  // candump -l may append a direction/flags field (" T", " R"); ignore it.
  const auto sp3 = rest.find(' ');
  if (sp3 != std::string_view::npos) rest = rest.substr(0, sp3);
  if (!parse_frame(rest, out, error)) {
    error = "frame '" + std::string(rest.substr(0, 40)) + "': " + error;
    return false;
  }
  return true;
}

CandumpLogWriter::CandumpLogWriter(const std::string& path, std::string interface)
    : path_(path), interface_(std::move(interface)) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) {
    throw std::runtime_error("cannot open CAN log '" + path +
                             "' for writing: " + std::strerror(errno));
  }
}

CandumpLogWriter::~CandumpLogWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void CandumpLogWriter::write(const hal::CanFrame& frame, uint64_t t_ns) {
  const std::string line = format_candump_line(frame, t_ns, interface_);
  if (std::fprintf(file_, "%s\n", line.c_str()) < 0) {
    throw std::runtime_error("write to CAN log '" + path_ + "' failed");
  }
  ++frames_written_;
}

void CandumpLogWriter::flush() {
  if (std::fflush(file_) != 0) {
    throw std::runtime_error("flush of CAN log '" + path_ + "' failed");
  }
}

bool CandumpLogReader::next(LoggedFrame& out) {
  while (std::getline(in_, buf_)) {
    ++line_;
    std::string_view v = buf_;
    while (!v.empty() && (v.back() == '\r' || v.back() == ' ' || v.back() == '\t'))
      v.remove_suffix(1);
    if (v.empty()) continue;
    std::string error;
    if (!parse_candump_line(v, out, error)) throw CandumpError(line_, error);
    return true;
  }
  return false;
}

}  // namespace hrg::can
