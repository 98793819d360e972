// SPDX-License-Identifier: MIT
#include "recording/recording.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

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
  if (in.bad()) throw RecordingError(name, 0, "", "read error");
  return ss.str();
}

}  // namespace

bool parse_number(std::string_view cell, double& out, bool& not_finite) {
  not_finite = false;
  cell = trim(cell);
  if (cell.empty()) return false;
  if (cell.front() == '+') {
    cell.remove_prefix(1);
    // from_chars takes a '-' of its own: "+-1" is two signs, not a number.
    if (cell.empty() || cell.front() == '-') return false;
  }
  const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), out);
  if (r.ec != std::errc() || r.ptr != cell.data() + cell.size()) return false;
  if (!std::isfinite(out)) {
    not_finite = true;
    return false;
  }
  return true;
}

namespace {

// The value of a numeric metadata key, parsed as strictly as a data cell.
double number_of(const std::string& key, const std::string& value) {
  double v = 0.0;
  bool not_finite = false;
  if (!parse_number(value, v, not_finite)) {
    throw std::invalid_argument("recording: metadata '" + key + "' is not a finite number: '" +
                                value + "'");
  }
  return v;
}

}  // namespace

bool is_gzip(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

std::string gunzip(std::string_view bytes, const std::string& source) {
  z_stream z{};
  // 16 + MAX_WBITS: gzip framing only (header, CRC-32 and length checked).
  if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK)
    throw RecordingError(source, 0, "", "cannot start the gzip decoder");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(bytes.size());
  std::string text;
  char buf[1 << 15];
  int rc = Z_OK;
  // One member after another (concatenated gzip files are one stream).
  while (rc != Z_STREAM_END || z.avail_in > 0) {
    if (rc == Z_STREAM_END) inflateReset(&z);
    z.next_out = reinterpret_cast<Bytef*>(buf);
    z.avail_out = sizeof buf;
    rc = inflate(&z, Z_NO_FLUSH);
    text.append(buf, sizeof buf - z.avail_out);
    if (rc == Z_OK || rc == Z_STREAM_END) continue;
    const std::size_t at = bytes.size() - z.avail_in;
    const std::string why = z.msg ? z.msg : "zlib error " + std::to_string(rc);
    inflateEnd(&z);
    if (rc == Z_BUF_ERROR) {
      throw RecordingError(source, 0, "",
                           "truncated gzip stream: it ends after " + std::to_string(at) +
                               " compressed bytes (" + std::to_string(text.size()) +
                               " bytes decompressed) before its end-of-stream marker");
    }
    throw RecordingError(
        source, 0, "",
        "corrupt gzip data at compressed byte " + std::to_string(at) + " (" + why + ")");
  }
  inflateEnd(&z);
  return text;
}

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
  if (key == "f_ref_hz") f_ref_hz_ = number_of(key, value);
  if (key == "angular_gain") angular_gain_ = number_of(key, value);
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

namespace detail {

// parse_recording's steps: the version line, metadata lines up to the
// header, the header, then one data row per line.
class RecordingParser {
 public:
  explicit RecordingParser(const std::string& source) : source_(source) {}

  void line(std::string_view line, std::size_t line_no) {
    line_no_ = line_no;
    if (line_no == 1) return version_line(line);
    if (!have_header_ && !line.empty() && line.front() == '#') return metadata_line(line);
    if (trim(line).empty()) return;
    if (!have_header_) return header_line(line);
    data_row(line);
  }

  Recording finish() {
    if (!have_header_) throw error("", "no header line found");
    if (rec_.rows() == 0) throw error("", "no data rows");
    rec_.find_gaps(row_lines_);
    return std::move(rec_);
  }

 private:
  RecordingError error(const std::string& column, const std::string& msg) const {
    return RecordingError(source_, line_no_, column, msg);
  }

  void version_line(std::string_view line) {
    if (trim(line) != "# hrg-recording v1") {
      throw error("",
                  "first line must be '# hrg-recording v1' (not an hrg recording, "
                  "or another version)");
    }
  }

  // '# key = value'; a comment line without '=' is free text.
  void metadata_line(std::string_view line) {
    const std::string_view body = trim(line.substr(1));
    const std::size_t eq = body.find('=');
    if (eq == std::string_view::npos) return;
    const std::string key(trim(body.substr(0, eq)));
    const std::string value(trim(body.substr(eq + 1)));
    if (key.empty()) throw error("", "metadata line without a key");
    double v = 0.0;
    bool not_finite = false;
    const auto& req = kRequiredMetadata;
    if (std::find(std::begin(req), std::end(req), key) != std::end(req) &&
        !parse_number(value, v, not_finite)) {
      throw error("", "metadata '" + key + "' is not a finite number: '" + value + "'");
    }
    rec_.set_metadata(key, value);
  }

  void header_line(std::string_view line) {
    for (auto cell : split_commas(line)) {
      const std::string name(trim(cell));
      if (name.empty()) throw error("", "empty column name in header");
      if (rec_.has_column(name)) throw error(name, "column named twice in the header");
      rec_.columns_.push_back(name);
    }
    for (auto req : kRequiredColumns) {
      if (!rec_.has_column(req))
        throw error(std::string(req), "required column missing from the header");
    }
    for (auto req : kRequiredMetadata) {
      if (rec_.metadata_value(req).empty())
        throw error("", "required metadata '" + std::string(req) + "' missing before the header");
    }
    const auto& cols = rec_.columns_;
    rec_.data_.resize(cols.size());
    t_col_ = static_cast<std::size_t>(std::find(cols.begin(), cols.end(), "t_s") - cols.begin());
    exc_col_ = static_cast<std::size_t>(std::find(cols.begin(), cols.end(), "exc") - cols.begin());
    row_.resize(cols.size());
    have_header_ = true;
  }

  void data_row(std::string_view line) {
    const auto cells = split_commas(line);
    if (cells.size() != rec_.columns_.size()) {
      throw error("", "row has " + std::to_string(cells.size()) + " cells, header has " +
                          std::to_string(rec_.columns_.size()) + " columns");
    }
    for (std::size_t c = 0; c < cells.size(); ++c) {
      bool not_finite = false;
      if (!parse_number(cells[c], row_[c], not_finite)) {
        throw error(rec_.columns_[c], "column " + std::to_string(c + 1) + ": '" +
                                          std::string(trim(cells[c])) + "' is " +
                                          (not_finite ? "NaN or infinite" : "not a number"));
      }
    }
    if (row_[exc_col_] != 0.0 && row_[exc_col_] != 1.0)
      throw error("exc", "must be 0 or 1, got '" + std::string(trim(cells[exc_col_])) + "'");
    const auto& t = rec_.data_[t_col_];
    if (!t.empty() && !(row_[t_col_] > t.back())) {
      throw error("t_s", "time does not increase (" + std::string(trim(cells[t_col_])) +
                             " after line " + std::to_string(row_lines_.back()) + ")");
    }
    for (std::size_t c = 0; c < row_.size(); ++c)
      rec_.data_[c].push_back(row_[c]);
    row_lines_.push_back(line_no_);
  }

  const std::string& source_;
  Recording rec_;
  std::size_t line_no_ = 0;
  bool have_header_ = false;
  std::size_t t_col_ = 0;
  std::size_t exc_col_ = 0;
  std::vector<double> row_;
  std::vector<std::size_t> row_lines_;
};

}  // namespace detail

Recording parse_recording(std::string_view text, const std::string& source) {
  detail::RecordingParser parser(source);
  std::size_t pos = 0;
  std::size_t line_no = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    parser.line(line, ++line_no);
  }
  return parser.finish();
}

Recording read_recording(const std::filesystem::path& path) {
  const std::string bytes = read_file_bytes(path);
  if (!is_gzip(bytes)) return parse_recording(bytes, path.string());
  return parse_recording(gunzip(bytes, path.string()), path.string());
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
