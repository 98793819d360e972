// SPDX-License-Identifier: MIT
#pragma once

#include "hal/gpio.hpp"

struct gpiod_chip;
struct gpiod_line;

namespace hrg::hal::linux_board {

// Where a line is: `chip` is anything gpiod_chip_open_lookup() accepts (name
// "gpiochip0", path "/dev/gpiochip0", label, or number); `offset` is the line
// on that chip. `active_low` inverts the electrical level (write(true) drives
// the pin low), for enable inputs that are active low on the board.
struct LineConfig {
  const char* chip = "gpiochip0";
  unsigned offset = 0;
  bool active_low = false;
  const char* consumer = "hrg";
};

// One output line through libgpiod v1 (Debian 12 ships 1.6). The line is
// requested at open() and driven inactive; the request is released (the line
// floats back to its default) when the object is destroyed.
class GpiodOutput final : public DigitalOut {
 public:
  GpiodOutput() = default;
  ~GpiodOutput() override;
  // invalid_argument: no such chip or line; busy: the line is requested by
  // someone else; io_error otherwise.
  Status open(const LineConfig& config);
  void close();
  Status write(bool active) override;

 private:
  gpiod_chip* chip_ = nullptr;
  gpiod_line* line_ = nullptr;
};

// One input line through libgpiod v1.
class GpiodInput final : public DigitalIn {
 public:
  GpiodInput() = default;
  ~GpiodInput() override;
  Status open(const LineConfig& config);
  void close();
  Status read(bool& active) override;

 private:
  gpiod_chip* chip_ = nullptr;
  gpiod_line* line_ = nullptr;
};

}  // namespace hrg::hal::linux_board
