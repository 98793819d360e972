// SPDX-License-Identifier: MIT
#include "sim_run/console.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdarg>
#include <thread>

namespace hrg::sim_run {

uint64_t HostClock::now_ns() const {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

hal::Status HostClock::sleep_until_ns(uint64_t t_ns) {
  const uint64_t now = now_ns();
  if (t_ns < now) return hal::Status::timeout;
  std::this_thread::sleep_for(std::chrono::nanoseconds(t_ns - now));
  return hal::Status::ok;
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(double total, bool enabled) : total_(total), enabled_(enabled) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double done, const char* label) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  drawn_ = true;
  const double f = total_ > 0 ? std::clamp(done / total_, 0.0, 1.0) : 1.0;
  constexpr int kWidth = 40;
  const int fill = static_cast<int>(f * kWidth);
  std::fprintf(stderr, "\r[%.*s%*s] %5.1f%%  %-30s", fill,
               "########################################", kWidth - fill, "", 100.0 * f, label);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (enabled_ && drawn_) {
    std::fprintf(stderr, "\r%*s\r", 90, "");
    std::fflush(stderr);
  }
  drawn_ = false;
  enabled_ = false;
}

void TextTable::print(std::FILE* out) const {
  std::vector<std::size_t> width;
  for (const auto& r : rows_) {
    if (width.size() < r.size()) width.resize(r.size(), 0);
    for (std::size_t i = 0; i < r.size(); ++i)
      width[i] = std::max(width[i], r[i].size());
  }
  std::fprintf(out, "%s\n", title_.c_str());
  for (const auto& r : rows_) {
    std::fprintf(out, " ");
    for (std::size_t i = 0; i < r.size(); ++i) {
      std::fprintf(out, " %-*s", static_cast<int>(width[i]), r[i].c_str());
    }
    std::fprintf(out, "\n");
  }
}

std::string fmt(const char* format, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, format);
  std::vsnprintf(buf, sizeof buf, format, ap);
  va_end(ap);
  return buf;
}

}  // namespace hrg::sim_run
