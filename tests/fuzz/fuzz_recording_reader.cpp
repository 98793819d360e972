// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary bytes through the hrg-recording reader, as
// read_recording takes a file: gzip (by its magic) is inflated first, then the
// text is parsed. Every input either reads or throws RecordingError naming the
// source, a stream error with line 0 and a text error on a line of the text;
// a recording that reads has what the format promises (required columns and
// metadata, finite cells, strictly increasing t_s, exc 0 or 1, gaps inside it).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "recording/recording.hpp"

using namespace hrg::recording;

namespace {

void check_read(const Recording& r) {
  if (r.rows() == 0 || !std::isfinite(r.f_ref_hz()) || !std::isfinite(r.angular_gain()))
    std::abort();
  for (auto req : kRequiredColumns) {
    if (!r.has_column(req)) std::abort();
  }
  for (const auto& name : r.column_names()) {
    const auto& c = r.column(name);
    if (c.size() != r.rows() ||
        !std::all_of(c.begin(), c.end(), [](double v) { return std::isfinite(v); })) {
      std::abort();
    }
  }
  const auto& t = r.column("t_s");
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!(t[i] > t[i - 1])) std::abort();
  }
  for (double e : r.column("exc")) {
    if (e != 0.0 && e != 1.0) std::abort();
  }
  for (const Gap& g : r.gaps()) {
    if (g.row == 0 || g.row >= r.rows() || !(g.t_after_s > g.t_before_s)) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string source = "fuzz.csv.gz";
  std::string text(bytes);
  if (is_gzip(bytes)) {
    try {
      text = gunzip(bytes, source);
    } catch (const RecordingError& e) {
      if (e.line() != 0 || e.source() != source) std::abort();
      return 0;
    }
  }
  try {
    check_read(parse_recording(text, source));
  } catch (const RecordingError& e) {
    const std::size_t lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
    if (e.source() != source || e.line() > lines + 1) std::abort();
    if (std::string_view(e.what()).find(source) == std::string_view::npos) std::abort();
  }
  return 0;
}
