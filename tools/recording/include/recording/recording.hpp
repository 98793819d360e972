// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

// hrg-recording v1: the interchange format for demodulated resonator signals
// (docs/recording-format.md). Host-only: uses the heap, exceptions and zlib.
namespace hrg::recording {

namespace detail {
class RecordingParser;
}

// Parses a whole text (spaces and tabs around it aside) as a finite double,
// the one rule for every number of a recording, cells and header alike: an
// optional '+' or '-', no other text; false for anything else, with
// `not_finite` set for an infinity or a NaN.
bool parse_number(std::string_view text, double& out, bool& not_finite);

// A malformed recording. `line` is 1-based (0 when the problem is not on one
// line, e.g. a missing metadata key); `column` is the column name when the
// problem is in one cell or column, empty otherwise. what() says all of it.
class RecordingError : public std::runtime_error {
 public:
  RecordingError(std::string source, std::size_t line, std::string column, const std::string& msg);
  std::size_t line() const { return line_; }
  const std::string& column() const { return column_; }
  const std::string& source() const { return source_; }

 private:
  std::string source_;
  std::size_t line_;
  std::string column_;
};

// A hole in the sampling: the step from row `row - 1` to row `row` is much
// longer than the typical step. Reported, never filled in.
struct Gap {
  std::size_t row = 0;           // index of the first row after the gap
  std::size_t line = 0;          // file line of that row
  double t_before_s = 0.0;       // time of the last row before the gap
  double t_after_s = 0.0;        // time of the first row after the gap
  double missing_samples = 0.0;  // (t_after - t_before) / typical step - 1
};

// Columns every recording has; the rest are optional or unknown-but-kept.
inline constexpr std::string_view kRequiredColumns[] = {"t_s",  "cx_v", "sx_v",
                                                        "cy_v", "sy_v", "exc"};
inline constexpr std::string_view kRequiredMetadata[] = {"f_ref_hz", "angular_gain"};

// One recording in memory, column-major. Column order and metadata order are
// those of the file, so a read-write round trip keeps unknown columns and keys.
class Recording {
 public:
  Recording() = default;
  // An empty recording with these columns (must include the required ones)
  // and the required metadata set.
  Recording(std::vector<std::string> columns, double f_ref_hz, double angular_gain);

  std::size_t rows() const { return columns_.empty() ? 0 : data_.front().size(); }
  const std::vector<std::string>& column_names() const { return columns_; }
  bool has_column(std::string_view name) const;
  // Values of a column; throws std::out_of_range naming the column if absent.
  const std::vector<double>& column(std::string_view name) const;
  std::vector<double>& column(std::string_view name);
  // Appends a row given in column_names() order; throws std::invalid_argument
  // on a size mismatch.
  void append_row(const std::vector<double>& values);
  // Adds an optional or extra column filled with `fill` for existing rows.
  void add_column(const std::string& name, double fill = 0.0);

  const std::vector<std::pair<std::string, std::string>>& metadata() const { return metadata_; }
  // Value of a metadata key, or empty when absent.
  std::string metadata_value(std::string_view key) const;
  void set_metadata(const std::string& key, const std::string& value);

  double f_ref_hz() const { return f_ref_hz_; }
  double angular_gain() const { return angular_gain_; }
  const std::vector<Gap>& gaps() const { return gaps_; }
  // Median sampling step of t_s (0 with fewer than two rows).
  double typical_step_s() const;

  // Rebuilds gaps() from t_s: a step longer than 1.5 typical steps is a gap.
  void find_gaps(const std::vector<std::size_t>& row_lines = {});

 private:
  friend class detail::RecordingParser;
  std::vector<std::string> columns_;
  std::vector<std::vector<double>> data_;
  std::vector<std::pair<std::string, std::string>> metadata_;
  double f_ref_hz_ = 0.0;
  double angular_gain_ = 0.0;
  std::vector<Gap> gaps_;
};

// Shortest text that reads back to exactly `v` (as written in cells).
std::string format_number(double v);

// Parses the text of a recording. `source` names it in error messages.
// Throws RecordingError for anything malformed (see the format doc).
Recording parse_recording(std::string_view text, const std::string& source);

// True when `bytes` start with the gzip magic (1f 8b).
bool is_gzip(std::string_view bytes);

// Decompresses gzip data held in memory (one member or several in a row).
// Throws RecordingError (line 0) naming `source` for a truncated stream (and
// how far it got) or corrupt data (and at which compressed byte).
std::string gunzip(std::string_view bytes, const std::string& source);

// Reads a .csv or .csv.gz file (gzip detected from the magic bytes).
// Throws RecordingError (with line 0) when the file cannot be read or its
// gzip stream is truncated or corrupt.
Recording read_recording(const std::filesystem::path& path);

// Writes the whole recording; gzip-compressed when the name ends in ".gz".
// Throws std::runtime_error naming the path when it cannot be written.
void write_recording(const std::filesystem::path& path, const Recording& rec);

}  // namespace hrg::recording
