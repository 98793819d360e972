// SPDX-License-Identifier: MIT
#include "batch/batch.hpp"

#include <cctype>
#include <cstdlib>

namespace hrg::batch {

unsigned all_cores() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : n;
}

bool parse_jobs(const std::string& text, unsigned& jobs) {
  if (text.empty() || text.size() > 6) return false;
  for (const char c : text) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  }
  jobs = static_cast<unsigned>(std::strtoul(text.c_str(), nullptr, 10));
  if (jobs == 0) jobs = all_cores();
  return true;
}

}  // namespace hrg::batch
