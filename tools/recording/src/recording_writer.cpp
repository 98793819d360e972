// SPDX-License-Identifier: MIT
#include "recording/recording_writer.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "recording/recording.hpp"

namespace hrg::recording {

std::string format_number(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// Plain or gzip output behind one interface.
struct RecordingWriter::Sink {
  std::string path;
  std::FILE* plain = nullptr;
  gzFile gz = nullptr;

  void write(const std::string& s) {
    if (s.empty()) return;
    bool ok = false;
    if (gz != nullptr) {
      ok = gzwrite(gz, s.data(), static_cast<unsigned>(s.size())) == static_cast<int>(s.size());
    } else if (plain != nullptr) {
      ok = std::fwrite(s.data(), 1, s.size(), plain) == s.size();
    }
    if (!ok) throw std::runtime_error(path + ": write failed");
  }
  void close() {
    bool ok = true;
    if (gz != nullptr) ok = gzclose(gz) == Z_OK;
    if (plain != nullptr) ok = std::fclose(plain) == 0 && ok;
    gz = nullptr;
    plain = nullptr;
    if (!ok) throw std::runtime_error(path + ": closing the file failed");
  }
};

RecordingWriter::RecordingWriter(const std::filesystem::path& path,
                                 std::vector<std::string> columns, double f_ref_hz,
                                 double angular_gain,
                                 const std::vector<std::pair<std::string, std::string>>& extra)
    : sink_(std::make_unique<Sink>()), columns_(std::move(columns)) {
  for (auto req : kRequiredColumns) {
    const auto it = std::find(columns_.begin(), columns_.end(), req);
    if (it == columns_.end()) {
      throw std::invalid_argument("recording writer: required column '" + std::string(req) +
                                  "' missing");
    }
  }
  for (const auto& c : columns_) {
    if (c.empty() || c.find_first_of(",\n\r") != std::string::npos ||
        std::count(columns_.begin(), columns_.end(), c) != 1) {
      throw std::invalid_argument("recording writer: bad or repeated column name '" + c + "'");
    }
  }
  if (!std::isfinite(f_ref_hz) || !std::isfinite(angular_gain)) {
    throw std::invalid_argument("recording writer: f_ref_hz and angular_gain must be finite");
  }
  t_index_ = static_cast<std::size_t>(std::find(columns_.begin(), columns_.end(), "t_s") -
                                      columns_.begin());
  exc_index_ = static_cast<std::size_t>(std::find(columns_.begin(), columns_.end(), "exc") -
                                        columns_.begin());
  sink_->path = path.string();
  const std::string name = path.filename().string();
  const bool gz = name.size() > 3 && name.compare(name.size() - 3, 3, ".gz") == 0;
  if (gz) {
    sink_->gz = gzopen(sink_->path.c_str(), "wb6");
  } else {
    sink_->plain = std::fopen(sink_->path.c_str(), "wb");
  }
  if (sink_->gz == nullptr && sink_->plain == nullptr) {
    throw std::runtime_error(sink_->path + ": cannot open for writing");
  }
  std::string head = "# hrg-recording v1\n";
  head += "# f_ref_hz=" + format_number(f_ref_hz) + "\n";
  head += "# angular_gain=" + format_number(angular_gain) + "\n";
  for (const auto& [k, v] : extra) {
    if (k == "f_ref_hz" || k == "angular_gain") continue;
    if (k.empty() || k.find_first_of("=\n\r") != std::string::npos ||
        v.find_first_of("\n\r") != std::string::npos) {
      throw std::invalid_argument("recording writer: bad metadata key or value '" + k + "'");
    }
    head += "# " + k + "=" + v + "\n";
  }
  for (std::size_t c = 0; c < columns_.size(); ++c)
    head += (c ? "," : "") + columns_[c];
  head += "\n";
  sink_->write(head);
}

RecordingWriter::~RecordingWriter() {
  try {
    close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
  }
}

void RecordingWriter::write_row(std::span<const double> values) {
  if (sink_->gz == nullptr && sink_->plain == nullptr) {
    throw std::runtime_error(sink_->path + ": row written after close");
  }
  if (values.size() != columns_.size()) {
    throw std::invalid_argument(sink_->path + ": row " + std::to_string(rows_ + 1) + " has " +
                                std::to_string(values.size()) + " values for " +
                                std::to_string(columns_.size()) + " columns");
  }
  for (std::size_t c = 0; c < values.size(); ++c) {
    if (!std::isfinite(values[c])) {
      throw std::invalid_argument(sink_->path + ": row " + std::to_string(rows_ + 1) +
                                  ", column '" + columns_[c] + "': value is not finite");
    }
  }
  const double exc = values[exc_index_];
  if (exc != 0.0 && exc != 1.0) {
    throw std::invalid_argument(sink_->path + ": row " + std::to_string(rows_ + 1) +
                                ", column 'exc': must be 0 or 1");
  }
  const double t = values[t_index_];
  if (rows_ > 0 && !(t > last_t_s_)) {
    throw std::invalid_argument(sink_->path + ": row " + std::to_string(rows_ + 1) +
                                ", column 't_s': time does not increase");
  }
  line_.clear();
  char buf[64];
  for (std::size_t c = 0; c < values.size(); ++c) {
    if (c) line_.push_back(',');
    const auto r = std::to_chars(buf, buf + sizeof buf, values[c]);
    line_.append(buf, r.ptr);
  }
  line_.push_back('\n');
  sink_->write(line_);
  last_t_s_ = t;
  ++rows_;
}

void RecordingWriter::close() {
  if (sink_) sink_->close();
}

}  // namespace hrg::recording
