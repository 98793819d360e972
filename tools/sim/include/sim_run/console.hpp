// SPDX-License-Identifier: MIT
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "hal/clock.hpp"

namespace hrg::sim_run {

// Host monotonic clock (std::chrono::steady_clock), for timing tasks in
// lockstep where the simulated clock does not move while a task runs.
class HostClock final : public hal::MonotonicClock {
 public:
  uint64_t now_ns() const override;
  hal::Status sleep_until_ns(uint64_t t_ns) override;
};

// A one-line progress bar on stderr, drawn only when stderr is a terminal and
// at most ten times a second.
class ProgressBar {
 public:
  explicit ProgressBar(double total, bool enabled);
  ~ProgressBar();
  void update(double done, const char* label);
  void finish();

 private:
  double total_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_{};
};

bool stderr_is_terminal();

// A plain text table: a title, rows of cells, columns padded to fit.
class TextTable {
 public:
  explicit TextTable(std::string title) : title_(std::move(title)) {}
  void row(std::vector<std::string> cells) { rows_.push_back(std::move(cells)); }
  void print(std::FILE* out) const;

 private:
  std::string title_;
  std::vector<std::vector<std::string>> rows_;
};

// printf into a std::string.
std::string fmt(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace hrg::sim_run
