// SPDX-License-Identifier: MIT
#pragma once

#include <array>

#include "hal/temperature.hpp"

namespace hrg::hal::linux_board {

// A temperature channel the kernel exposes as a file of millidegrees Celsius:
// an IIO `in_temp*_input` (/sys/bus/iio/devices/iio:deviceN/in_temp0_input)
// or a hwmon `temp*_input` (/sys/class/hwmon/hwmonN/temp1_input). The file
// stays open; every read() re-reads it from offset 0 (sysfs gives a fresh
// conversion per read). Content: an optional sign, decimal digits, optional
// trailing whitespace (the kernel's newline); anything else is io_error and
// error() names the path and what was found.
class FileTemperatureSensor final : public TemperatureSensor {
 public:
  FileTemperatureSensor() = default;
  ~FileTemperatureSensor() override;

  // Opens `path` and reads it once: ok, or closed (cannot be opened) or
  // io_error (the content is not millidegrees), error() saying why.
  Status open(const char* path);
  Status read(double& temp_c) override;
  void close();
  bool is_open() const { return fd_ >= 0; }
  // "" after a good read, else one line naming the path and the problem.
  const char* error() const { return error_.data(); }

 private:
  void set_error(const char* what, const char* detail);

  int fd_ = -1;
  std::array<char, 256> path_{};
  std::array<char, 384> error_{};
};

// Millidegrees Celsius in `text` (n characters) as degC: false when it is not
// an optional sign, 1 to 9 decimal digits and optional trailing whitespace.
bool parse_millidegrees(const char* text, std::size_t n, double& temp_c);

}  // namespace hrg::hal::linux_board
