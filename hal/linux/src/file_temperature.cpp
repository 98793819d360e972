// SPDX-License-Identifier: MIT
#include "hal/linux/file_temperature.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

namespace hrg::hal::linux_board {

namespace {
bool is_space(char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r'; }
}  // namespace

bool parse_millidegrees(const char* text, std::size_t n, double& temp_c) {
  std::size_t i = 0;
  bool negative = false;
  if (i < n && (text[i] == '-' || text[i] == '+')) negative = text[i++] == '-';
  long long milli = 0;
  std::size_t digits = 0;
  for (; i < n && text[i] >= '0' && text[i] <= '9'; ++i, ++digits) {
    if (digits == 9) return false;  // beyond +-1e6 degC: not a temperature
    milli = milli * 10 + (text[i] - '0');
  }
  if (digits == 0) return false;
  for (; i < n; ++i) {
    if (!is_space(text[i])) return false;
  }
  temp_c = static_cast<double>(negative ? -milli : milli) * 1e-3;
  return true;
}

FileTemperatureSensor::~FileTemperatureSensor() { close(); }

void FileTemperatureSensor::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void FileTemperatureSensor::set_error(const char* what, const char* detail) {
  std::snprintf(error_.data(), error_.size(), "temperature sensor %s: %s%s", path_.data(), what,
                detail);
}

Status FileTemperatureSensor::open(const char* path) {
  close();
  std::snprintf(path_.data(), path_.size(), "%s", path);
  fd_ = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    set_error("cannot open: ", std::strerror(errno));
    return Status::closed;
  }
  double first = 0.0;
  const Status st = read(first);
  if (st != Status::ok) close();
  return st == Status::ok ? Status::ok : Status::io_error;
}

Status FileTemperatureSensor::read(double& temp_c) {
  if (fd_ < 0) return Status::closed;
  std::array<char, 32> buf{};
  const ssize_t n = ::pread(fd_, buf.data(), buf.size() - 1, 0);
  if (n < 0) {
    set_error("read failed: ", std::strerror(errno));
    return Status::io_error;
  }
  double v = 0.0;
  if (!parse_millidegrees(buf.data(), static_cast<std::size_t>(n), v)) {
    // Shown as read, up to the first line end.
    std::array<char, 40> shown{};
    std::snprintf(shown.data(), shown.size(), "'%.*s'",
                  static_cast<int>(std::strcspn(buf.data(), "\n")), buf.data());
    set_error("content is not millidegrees Celsius (an integer): ", shown.data());
    return Status::io_error;
  }
  error_[0] = '\0';
  temp_c = v;
  return Status::ok;
}

}  // namespace hrg::hal::linux_board
