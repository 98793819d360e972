// SPDX-License-Identifier: MIT
#include "hal/linux/gpiod_line.hpp"

#include <gpiod.h>

#include <cerrno>

namespace hrg::hal::linux_board {

namespace {

Status request(const LineConfig& c, bool output, gpiod_chip*& chip, gpiod_line*& line) {
  chip = gpiod_chip_open_lookup(c.chip);
  if (chip == nullptr) return Status::invalid_argument;
  line = gpiod_chip_get_line(chip, c.offset);
  if (line == nullptr) {
    gpiod_chip_close(chip);
    chip = nullptr;
    return Status::invalid_argument;
  }
  const int flags = c.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
  const int r = output ? gpiod_line_request_output_flags(line, c.consumer, flags, 0)
                       : gpiod_line_request_input_flags(line, c.consumer, flags);
  if (r < 0) {
    const int err = errno;
    gpiod_chip_close(chip);  // also releases the line
    chip = nullptr;
    line = nullptr;
    return err == EBUSY ? Status::busy : Status::io_error;
  }
  return Status::ok;
}

void release(gpiod_chip*& chip, gpiod_line*& line) {
  if (line != nullptr) gpiod_line_release(line);
  if (chip != nullptr) gpiod_chip_close(chip);
  chip = nullptr;
  line = nullptr;
}

}  // namespace

GpiodOutput::~GpiodOutput() { close(); }
void GpiodOutput::close() { release(chip_, line_); }

Status GpiodOutput::open(const LineConfig& config) {
  close();
  return request(config, true, chip_, line_);
}

Status GpiodOutput::write(bool active) {
  if (line_ == nullptr) return Status::closed;
  return gpiod_line_set_value(line_, active ? 1 : 0) == 0 ? Status::ok : Status::io_error;
}

GpiodInput::~GpiodInput() { close(); }
void GpiodInput::close() { release(chip_, line_); }

Status GpiodInput::open(const LineConfig& config) {
  close();
  return request(config, false, chip_, line_);
}

Status GpiodInput::read(bool& active) {
  if (line_ == nullptr) return Status::closed;
  const int v = gpiod_line_get_value(line_);
  if (v < 0) return Status::io_error;
  active = v != 0;
  return Status::ok;
}

}  // namespace hrg::hal::linux_board
