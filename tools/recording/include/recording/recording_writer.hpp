// SPDX-License-Identifier: MIT
#pragma once

#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace hrg::recording {

// Streams an hrg-recording v1 file row by row (telemetry, decoded CAN logs)
// without holding it in memory. gzip-compressed when the name ends in ".gz".
// Rows must come in strictly increasing t_s; values must be finite.
class RecordingWriter {
 public:
  // Opens `path` and writes the version line, the metadata (f_ref_hz and
  // angular_gain first, then `extra_metadata` in order) and the header.
  // `columns` must contain the required columns. Throws std::runtime_error
  // when the file cannot be opened, std::invalid_argument on bad columns.
  RecordingWriter(const std::filesystem::path& path, std::vector<std::string> columns,
                  double f_ref_hz, double angular_gain,
                  const std::vector<std::pair<std::string, std::string>>& extra_metadata = {});
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  // One row in the column order given to the constructor. Throws
  // std::invalid_argument on a size mismatch, a non-finite value or t_s not
  // increasing; std::runtime_error on a write failure.
  void write_row(std::span<const double> values);
  // Flushes and closes; further rows throw. Called by the destructor.
  void close();
  std::size_t rows_written() const { return rows_; }

 private:
  struct Sink;
  std::unique_ptr<Sink> sink_;
  std::vector<std::string> columns_;
  std::size_t t_index_ = 0;
  std::size_t exc_index_ = 0;
  double last_t_s_ = 0.0;
  std::size_t rows_ = 0;
  std::string line_;
};

}  // namespace hrg::recording
