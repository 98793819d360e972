// SPDX-License-Identifier: MIT
#include "firmware/calibration_file.hpp"

#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>

#include "toml_text/toml_text.hpp"

namespace hrg::fw {

namespace {

constexpr std::string_view kFormatKey = "calibration_format";
constexpr int64_t kFormat = 1;
constexpr std::string_view kSigmaSuffix = "_sigma";

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

bool is_angle(std::size_t field) { return ends_with(kCalibrationFields[field].key, "_rad"); }

[[noreturn]] void fail(const std::string& source, const toml::node* node, std::string_view key,
                       const std::string& what) {
  std::ostringstream msg;
  msg << source;
  if (node) msg << ":" << node->source().begin.line;
  msg << ": key '" << key << "': " << what;
  throw CalibrationFileError(msg.str());
}

double number_of(const toml::node& n, const std::string& source, std::string_view key) {
  if (auto d = n.value_exact<double>()) return *d;
  if (auto i = n.value_exact<int64_t>()) return static_cast<double>(*i);
  fail(source, &n, key, "must be a number");
}

// Full precision (a saved file loads back to the same double), or 15 digits for messages.
std::string fmt(double v, int digits = 17) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  std::string s(buf);
  // TOML floats need a '.' or an exponent.
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

// Field index and whether the key is its sigma; -1 when unknown.
int field_of_key(std::string_view key, bool& sigma) {
  sigma = ends_with(key, kSigmaSuffix);
  const std::string_view base = sigma ? key.substr(0, key.size() - kSigmaSuffix.size()) : key;
  for (std::size_t i = 0; i < kCalibrationFieldCount; ++i) {
    if (calibration_file_key(i) == base) return static_cast<int>(i);
  }
  return -1;
}

void check_format(const toml::table& root, const std::string& source) {
  const toml::node* f = root.get(kFormatKey);
  if (!f) fail(source, nullptr, kFormatKey, "is required (calibration_format = 1)");
  const auto v = f->value_exact<int64_t>();
  if (!v || *v != kFormat) fail(source, f, kFormatKey, "must be 1 (the only format this reads)");
}

void read_value(CalibrationFile& out, std::size_t i, bool sigma, const toml::node& n,
                const std::string& source, std::string_view key) {
  const CalibrationField& f = kCalibrationFields[i];
  const double file_v = number_of(n, source, key);
  const double v = file_v * calibration_file_to_si(i);
  if (sigma) {
    if (!(v >= 0.0 && std::isfinite(v))) fail(source, &n, key, "must be a finite number >= 0");
    out.sigma[i] = v;
    return;
  }
  if (!(v >= f.min && v <= f.max)) {
    const double k = 1.0 / calibration_file_to_si(i);
    fail(source, &n, key,
         fmt(file_v, 15) + " is out of range [" + fmt(f.min * k, 15) + ", " + fmt(f.max * k, 15) +
             "]");
  }
  out.calibration.*f.member = v;
}

void write_fields(std::ostream& s, const CalibrationFile& file) {
  s << kFormatKey << " = " << kFormat << "\n";
  for (std::size_t i = 0; i < kCalibrationFieldCount; ++i) {
    const double k = 1.0 / calibration_file_to_si(i);
    const std::string key = calibration_file_key(i);
    s << key << " = " << fmt(file.calibration.*kCalibrationFields[i].member * k) << "\n";
    if (std::isfinite(file.sigma[i])) {
      s << key << kSigmaSuffix << " = " << fmt(file.sigma[i] * k) << "\n";
    }
  }
}

}  // namespace

std::string calibration_file_key(std::size_t field) {
  std::string key = kCalibrationFields[field].key;
  if (is_angle(field)) key.replace(key.size() - 4, 4, "_deg");
  return key;
}

double calibration_file_to_si(std::size_t field) {
  return is_angle(field) ? std::numbers::pi / 180.0 : 1.0;
}

GapSigma gap_sigma(const CalibrationFile& file) {
  const auto sigma_of = [&file](double Calibration::*member) {
    for (std::size_t i = 0; i < kCalibrationFieldCount; ++i) {
      if (kCalibrationFields[i].member == member && std::isfinite(file.sigma[i]))
        return file.sigma[i];
    }
    return 0.0;
  };
  return {sigma_of(&Calibration::gap_eps_p), sigma_of(&Calibration::gap_eps_q)};
}

CalibrationFile parse_calibration(std::string_view text, const std::string& source) {
  toml::table root;
  try {
    root = toml_text::parse(text, source, "calibration files are ASCII, comments included");
  } catch (const toml_text::TextError& e) {
    throw CalibrationFileError(e.what());
  }
  check_format(root, source);
  CalibrationFile out;
  for (const auto& [k, node] : root) {
    const std::string_view key = k.str();
    if (key == kFormatKey) continue;
    bool sigma = false;
    const int i = field_of_key(key, sigma);
    if (i < 0) fail(source, &node, key, "unknown key");
    read_value(out, static_cast<std::size_t>(i), sigma, node, source, key);
  }
  return out;
}

CalibrationFile load_calibration(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw CalibrationFileError(path + ": cannot open calibration file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_calibration(text.str(), path);
}

std::string format_calibration(const CalibrationFile& file, const std::vector<std::string>& header,
                               const std::vector<std::string>& footer) {
  std::ostringstream body;
  write_fields(body, file);
  // The CRC of what this text loads as (degrees do not convert back to the
  // same radians bit for bit, so it is taken after the round trip).
  const Calibration loaded = parse_calibration(body.str(), "(formatted)").calibration;
  char crc[16];
  std::snprintf(crc, sizeof crc, "0x%08X", calibration_crc(loaded));
  std::ostringstream s;
  for (const std::string& line : header)
    s << "#" << (line.empty() ? "" : " ") << line << "\n";
  s << "# CRC-32 of the canonical form (what the CAN block carries): " << crc << "\n";
  s << body.str();
  for (const std::string& line : footer)
    s << "#" << (line.empty() ? "" : " ") << line << "\n";
  return s.str();
}

std::string format_calibration_header(const Calibration& c, const std::string& source) {
  std::ostringstream s;
  char crc[16];
  std::snprintf(crc, sizeof crc, "0x%08X", calibration_crc(c));
  s << "// Generated by `hrg calibration-check " << source << " --header`: do not edit.\n"
    << "// CRC-32 of the canonical form: " << crc << "\n"
    << "#pragma once\n\n#include \"firmware/calibration.hpp\"\n\nnamespace hrg::fw {\n"
    << "constexpr Calibration kBuiltInCalibration{\n";
  for (const CalibrationField& f : kCalibrationFields) {
    char v[64];
    std::snprintf(v, sizeof v, "%a", c.*f.member);
    s << "    ." << f.key << " = " << v << ",  // " << fmt(c.*f.member, 15) << "\n";
  }
  s << "};\n}  // namespace hrg::fw\n";
  return s.str();
}

void save_calibration(const std::string& path, const CalibrationFile& file,
                      const std::vector<std::string>& header,
                      const std::vector<std::string>& footer) {
  std::ofstream out(path);
  if (!out) throw CalibrationFileError(path + ": cannot write calibration file");
  out << format_calibration(file, header, footer);
  if (!out.flush()) throw CalibrationFileError(path + ": write failed");
}

}  // namespace hrg::fw
