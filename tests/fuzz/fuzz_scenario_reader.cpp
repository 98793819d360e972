// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary text through the scenario (TOML) reader. Every
// input either gives a SimConfig whose values lie in the ranges the reader
// promises, or throws ScenarioError naming the source; nothing else escapes.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "sim_target/scenario.hpp"

using namespace hrg::sim;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // A rate or temperature table names a file to read: with no '/' in the
  // input, every name resolves inside a directory that does not exist, so
  // the target never reads the machine's files (a /dev/zero would never end).
  if (text.find('/') != std::string_view::npos) return 0;
  SimConfig c;
  try {
    c = parse_scenario(text, "fuzz.toml", "fuzz-no-such-dir");
  } catch (const ScenarioError& e) {
    if (std::string_view(e.what()).find("fuzz.toml") == std::string_view::npos) std::abort();
    return 0;
  }
  const auto& r = c.resonator;
  if (!(r.f_hz > 0) || !(r.q > 0) || !std::isfinite(r.f_hz) || !std::isfinite(r.q)) std::abort();
  if (c.adc.bits < 1 || c.adc.bits > 32 || c.adc.sample_rate_hz == 0 || c.adc.block_frames == 0)
    std::abort();
  if (!std::isfinite(c.rate_rad_s.value(0.0)) || !std::isfinite(c.temp_c.value(1.0))) std::abort();
  return 0;
}
