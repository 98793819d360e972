// SPDX-License-Identifier: MIT
#include "recording/recording.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "recording/recording_writer.hpp"

namespace hrg::recording {

namespace {

std::string describe(const std::string& source, std::size_t line, const std::string& column,
                     const std::string& msg) {
  std::string s = source;
  if (line > 0) s += ": line " + std::to_string(line);
  if (!column.empty()) s += ", column '" + column + "'";
  return s + ": " + msg;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

// Parses a whole cell as a finite double; false for anything else.
bool parse_number(std::string_view cell, double& out, bool& not_finite) {
  not_finite = false;
  cell = trim(cell);
  if (cell.empty()) return false;
  if (cell.front() == '+') cell.remove_prefix(1);
  const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), out);
  if (r.ec != std::errc() || r.ptr != cell.data() + cell.size()) return false;
  if (!std::isfinite(out)) {
    not_finite = true;
    return false;
  }
  return true;
}

std::vector<std::string_view> split_commas(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      cells.push_back(line.substr(start));
      return cells;
    }
    cells.push_back(line.substr(start, comma - start));
    start = comma + 1;
  }
}

std::string read_file_bytes(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RecordingError(name, 0, "", "cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  std::string raw = ss.str();
  const bool gz = raw.size() >= 2 && static_cast<unsigned char>(raw[0]) == 0x1f &&
                  static_cast<unsigned char>(raw[1]) == 0x8b;
  if (!gz) return raw;
  gzFile f = gzopen(name.c_str(), "rb");
  if (f == nullptr) throw RecordingError(name, 0, "", "cannot open the gzip stream");
  std::string text;
  text.reserve(raw.size() * 3);
  std::vector<char> buf(1 << 16);
  while (true) {
    const int n = gzread(f, buf.data(), static_cast<unsigned>(buf.size()));
    if (n < 0) {
      int err = 0;
      const std::string why = gzerror(f, &err);
      gzclose(f);
      throw RecordingError(name, 0, "", "corrupt gzip data (" + why + ")");
    }
    if (n == 0) break;
    text.append(buf.data(), static_cast<std::size_t>(n));
  }
  gzclose(f);
  return text;
}

}  // namespace

RecordingError::RecordingError(std::string source, std::size_t line, std::string column,
                               const std::string& msg)
    : std::runtime_error(describe(source, line, column, msg)),
      source_(std::move(source)),
      line_(line),
      column_(std::move(column)) {}

Recording::Recording(std::vector<std::string> columns, double f_ref_hz, double angular_gain)
    : columns_(std::move(columns)), f_ref_hz_(f_ref_hz), angular_gain_(angular_gain) {
  for (auto req : kRequiredColumns) {
    if (!has_column(req)) {
      throw std::invalid_argument("recording: required column '" + std::string(req) + "' missing");
    }
  }
  data_.resize(columns_.size());
  metadata_ = {{"f_ref_hz", format_number(f_ref_hz)},
               {"angular_gain", format_number(angular_gain)}};
}

bool Recording::has_column(std::string_view name) const {
  return std::find(columns_.begin(), columns_.end(), name) != columns_.end();
}

const std::vector<double>& Recording::column(std::string_view name) const {
  const auto it = std::find(columns_.begin(), columns_.end(), name);
  if (it == columns_.end()) {
    throw std::out_of_range("recording has no column '" + std::string(name) + "'");
  }
  return data_[static_cast<std::size_t>(it - columns_.begin())];
}

std::vector<double>& Recording::column(std::string_view name) {
  return const_cast<std::vector<double>&>(std::as_const(*this).column(name));
}

void Recording::append_row(const std::vector<double>& values) {
  if (values.size() != columns_.size()) {
    throw std::invalid_argument("recording: row has " + std::to_string(values.size()) +
                                " values for " + std::to_string(columns_.size()) + " columns");
  }
  for (std::size_t c = 0; c < values.size(); ++c)
    data_[c].push_back(values[c]);
}

void Recording::add_column(const std::string& name, double fill) {
  if (has_column(name)) throw std::invalid_argument("recording: column '" + name + "' exists");
  columns_.push_back(name);
  data_.emplace_back(rows(), fill);
}

std::string Recording::metadata_value(std::string_view key) const {
  for (const auto& [k, v] : metadata_) {
    if (k == key) return v;
  }
  return {};
}

void Recording::set_metadata(const std::string& key, const std::string& value) {
  if (key == "f_ref_hz") f_ref_hz_ = std::stod(value);
  if (key == "angular_gain") angular_gain_ = std::stod(value);
  for (auto& [k, v] : metadata_) {
    if (k == key) {
      v = value;
      return;
    }
  }
  metadata_.emplace_back(key, value);
}

double Recording::typical_step_s() const {
  if (rows() < 2 || !has_column("t_s")) return 0.0;
  const auto& t = column("t_s");
  std::vector<double> dt(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i)
    dt[i - 1] = t[i] - t[i - 1];
  auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  return *mid;
}

void Recording::find_gaps(const std::vector<std::size_t>& row_lines) {
  gaps_.clear();
  const double step = typical_step_s();
  if (step <= 0.0) return;
  const auto& t = column("t_s");
  for (std::size_t i = 1; i < t.size(); ++i) {
    const double dt = t[i] - t[i - 1];
    if (dt > 1.5 * step) {
      Gap g;
      g.row = i;
      g.line = i < row_lines.size() ? row_lines[i] : 0;
      g.t_before_s = t[i - 1];
      g.t_after_s = t[i];
      g.missing_samples = dt / step - 1.0;
      gaps_.push_back(g);
    }
  }
}

Recording parse_recording(std::string_view text, const std::string& source) {
  Recording rec;
  std::size_t pos = 0;
  std::size_t line_no = 0;
  bool have_header = false;
  std::vector<std::size_t> row_lines;
  std::size_t t_col = 0;
  std::size_t exc_col = 0;
  std::vector<double> row;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line_no == 1) {
      if (trim(line) != "# hrg-recording v1") {
        throw RecordingError(source, 1, "",
                             "first line must be '# hrg-recording v1' (not an hrg recording, "
                             "or another version)");
      }
      continue;
    }
    if (!have_header) {
      if (!line.empty() && line.front() == '#') {
        const std::string_view body = trim(line.substr(1));
        const std::size_t eq = body.find('=');
        if (eq == std::string_view::npos) continue;  // free comment line
        const std::string key(trim(body.substr(0, eq)));
        const std::string value(trim(body.substr(eq + 1)));
        if (key.empty()) throw RecordingError(source, line_no, "", "metadata line without a key");
        for (auto req : kRequiredMetadata) {
          double v = 0.0;
          bool nf = false;
          if (key == req && !parse_number(value, v, nf)) {
            throw RecordingError(source, line_no, "",
                                 "metadata '" + key + "' is not a finite number: '" + value + "'");
          }
        }
        rec.set_metadata(key, value);
        continue;
      }
      if (trim(line).empty()) continue;
      // Header line.
      for (auto cell : split_commas(line)) {
        const std::string name(trim(cell));
        if (name.empty()) throw RecordingError(source, line_no, "", "empty column name in header");
        if (rec.has_column(name)) {
          throw RecordingError(source, line_no, name, "column named twice in the header");
        }
        rec.columns_.push_back(name);
      }
      for (auto req : kRequiredColumns) {
        if (!rec.has_column(req)) {
          throw RecordingError(source, line_no, std::string(req),
                               "required column missing from the header");
        }
      }
      for (auto req : kRequiredMetadata) {
        if (rec.metadata_value(req).empty()) {
          throw RecordingError(
              source, line_no, "",
              "required metadata '" + std::string(req) + "' missing before the header");
        }
      }
      rec.data_.resize(rec.columns_.size());
      const auto& cols = rec.columns_;
      t_col = static_cast<std::size_t>(std::find(cols.begin(), cols.end(), "t_s") - cols.begin());
      exc_col = static_cast<std::size_t>(std::find(cols.begin(), cols.end(), "exc") - cols.begin());
      row.resize(cols.size());
      have_header = true;
      continue;
    }
    if (trim(line).empty()) continue;
    const auto cells = split_commas(line);
    if (cells.size() != rec.columns_.size()) {
      throw RecordingError(source, line_no, "",
                           "row has " + std::to_string(cells.size()) + " cells, header has " +
                               std::to_string(rec.columns_.size()) + " columns");
    }
    for (std::size_t c = 0; c < cells.size(); ++c) {
      bool not_finite = false;
      if (!parse_number(cells[c], row[c], not_finite)) {
        throw RecordingError(source, line_no, rec.columns_[c],
                             "column " + std::to_string(c + 1) + ": '" +
                                 std::string(trim(cells[c])) + "' is " +
                                 (not_finite ? "NaN or infinite" : "not a number"));
      }
    }
    if (row[exc_col] != 0.0 && row[exc_col] != 1.0) {
      throw RecordingError(source, line_no, "exc",
                           "must be 0 or 1, got '" + std::string(trim(cells[exc_col])) + "'");
    }
    if (!rec.data_[t_col].empty() && !(row[t_col] > rec.data_[t_col].back())) {
      throw RecordingError(source, line_no, "t_s",
                           "time does not increase (" + std::string(trim(cells[t_col])) +
                               " after line " + std::to_string(row_lines.back()) + ")");
    }
    for (std::size_t c = 0; c < row.size(); ++c)
      rec.data_[c].push_back(row[c]);
    row_lines.push_back(line_no);
  }
  if (!have_header) throw RecordingError(source, line_no, "", "no header line found");
  if (rec.rows() == 0) throw RecordingError(source, line_no, "", "no data rows");
  rec.find_gaps(row_lines);
  return rec;
}

Recording read_recording(const std::filesystem::path& path) {
  const std::string text = read_file_bytes(path);
  return parse_recording(text, path.string());
}

void write_recording(const std::filesystem::path& path, const Recording& rec) {
  std::vector<std::pair<std::string, std::string>> extra;
  for (const auto& kv : rec.metadata()) {
    if (kv.first != "f_ref_hz" && kv.first != "angular_gain") extra.push_back(kv);
  }
  RecordingWriter w(path, rec.column_names(), rec.f_ref_hz(), rec.angular_gain(), extra);
  std::vector<const std::vector<double>*> cols;
  for (const auto& name : rec.column_names())
    cols.push_back(&rec.column(name));
  std::vector<double> row(cols.size());
  for (std::size_t r = 0; r < rec.rows(); ++r) {
    for (std::size_t c = 0; c < cols.size(); ++c)
      row[c] = (*cols[c])[r];
    w.write_row(row);
  }
  w.close();
}

}  // namespace hrg::recording
