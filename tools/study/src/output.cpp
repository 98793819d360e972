// SPDX-License-Identifier: MIT
#include "study/output.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "sim_run/json.hpp"

namespace hrg::study {

namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();  // written as null

double or_none(double v) { return v < 0.0 ? kNone : v; }

// The JSON writer's indented text on one line.
std::string one_line(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\n') {
      out += text[i];
      continue;
    }
    while (i + 1 < text.size() && text[i + 1] == ' ')
      ++i;
  }
  return out;
}

void numbers(sim_run::JsonWriter& w, const char* key, const std::vector<double>& v) {
  w.begin_array(key);
  for (const double x : v)
    w.number(or_none(x));
  w.end_array();
}

void seed_json(sim_run::JsonWriter& w, const SeedResult& s) {
  w.begin_object();
  w.integer("seed", static_cast<long long>(s.seed));
  w.boolean("locked", s.locked);
  w.number("t_converged_s", or_none(s.t_converged_s));
  w.number("t_bias_start_s", or_none(s.t_bias_start_s));
  w.boolean("compensation_applied", s.comp_applied);
  w.integer("model_checks_failed", s.model_checks_failed);
  w.number("excitation_off", s.excitation_off);
  w.number("control_drift_mean_dph", s.control_drift_mean_dph);
  w.number("raw_adb_dph", or_none(s.raw_adb_dph));
  w.number("comp_adb_dph", or_none(s.comp_adb_dph));
  w.boolean("raw_parks_degenerate", s.raw_parks_degenerate);
  w.boolean("comp_parks_degenerate", s.comp_parks_degenerate);
  w.number("raw_bias_dph", s.raw_bias_dph);
  w.number("comp_bias_dph", s.comp_bias_dph);
  w.number("meas_sigma_dph", s.meas_sigma_dph);
  w.end_object();
}

void thresholds_json(sim_run::JsonWriter& w, const char* key, const std::array<double, 3>& v) {
  w.begin_object(key);
  const char* names[] = {"3", "0.1", "0.01"};
  for (std::size_t k = 0; k < v.size(); ++k)
    w.number(names[k], or_none(v[k]));
  w.end_object();
}

}  // namespace

std::string point_json_line(const PointResult& p) {
  sim_run::JsonWriter w;
  w.begin_object();
  w.integer("point", static_cast<long long>(p.spec.index));
  w.number("split_hz", p.spec.split_hz);
  w.number("dq_over_q", p.spec.dq_over_q);
  w.number("gap", p.spec.gap);
  w.number("q", p.spec.q);
  w.string("setup_error", p.setup_error);
  w.number("pump_needed_v", p.pump_needed_v);
  w.number("pump_max_v", p.pump_max_v);
  w.number("raw_adb_dph", or_none(p.raw_adb_dph));
  w.number("comp_adb_dph", or_none(p.comp_adb_dph));
  w.number("raw_bias_dph", p.raw_bias_dph);
  w.number("comp_bias_dph", p.comp_bias_dph);
  w.number("crb_adb_end_dph", or_none(p.crb_adb_end_dph));
  w.number("model_adb_end_dph", or_none(p.model_adb_end_dph));
  w.number("meas_sigma_dph", p.meas_sigma_dph);
  w.number("control_drift_mean_dph", p.control_drift_mean_dph);
  w.number("predicted_adb_dph", p.predicted_adb_dph);
  w.number("ratio", or_none(p.ratio));
  w.boolean("meets_bound", p.meets_bound);
  w.begin_array("reasons");
  for (const std::string& r : p.reasons)
    w.string({}, r);
  w.end_array();
  thresholds_json(w, "t_reach_s", p.t_reach_s);
  thresholds_json(w, "crb_at_reach_dph", p.crb_at_reach_dph);
  w.begin_array("per_seed");
  for (const SeedResult& s : p.seeds)
    seed_json(w, s);
  w.end_array();
  w.begin_object("series");
  numbers(w, "t_s", p.t_s);
  numbers(w, "model_adb_dph", p.model_adb_dph);
  numbers(w, "crb_adb_dph", p.crb_adb_dph);
  w.end_object();
  w.end_object();
  return one_line(w.str());
}

std::size_t point_index_of_line(const std::string& line, const std::string& where) {
  static const std::string kHead = "{\"point\": ";
  if (line.compare(0, kHead.size(), kHead) != 0)
    throw std::runtime_error(where + ": not a point line (it must start with {\"point\": K)");
  std::size_t end = kHead.size();
  while (end < line.size() && line[end] >= '0' && line[end] <= '9')
    ++end;
  if (end == kHead.size() || end - kHead.size() > 9 || end >= line.size() || line[end] != ',' ||
      line.back() != '}')
    throw std::runtime_error(where + ": malformed point line");
  return std::stoul(line.substr(kHead.size(), end - kHead.size()));
}

std::vector<std::string> read_point_lines(const std::string& path, const Grid& grid) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<std::string> lines(grid.points());
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::string where = path + ":" + std::to_string(n);
    const std::size_t k = point_index_of_line(line, where);
    if (k >= lines.size())
      throw std::runtime_error(where + ": point " + std::to_string(k) + " is outside the grid (" +
                               std::to_string(lines.size()) + " points)");
    if (!lines[k].empty())
      throw std::runtime_error(where + ": point " + std::to_string(k) + " given twice");
    lines[k] = line;
  }
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (lines[k].empty())
      throw std::runtime_error(path + ": point " + std::to_string(k) + " is missing");
  }
  return lines;
}

void write_study_json(const std::filesystem::path& dir, const Grid& grid,
                      const std::vector<std::string>& lines) {
  sim_run::JsonWriter head;
  head.begin_object();
  head.string("study", "tolerance");
  head.string("grid", grid.source);
  head.number("duration_s", grid.duration_s);
  head.integer("seeds", grid.seeds);
  head.integer("bias_angles", grid.bias_angles);
  head.number("sample_every_s", grid.sample_every_s);
  head.begin_array("thresholds_dph");
  for (const double t : kThresholdsDph)
    head.number(t);
  head.end_array();
  head.end_object();
  std::string text = one_line(head.str());
  text.pop_back();  // the closing brace: the points follow
  text += ", \"points\": [\n";
  for (std::size_t k = 0; k < lines.size(); ++k)
    text += lines[k] + (k + 1 < lines.size() ? ",\n" : "\n");
  text += "]}\n";
  std::ofstream out(dir / "study.json");
  out << text;
  if (!out) throw std::runtime_error((dir / "study.json").string() + ": cannot write");
}

}  // namespace hrg::study
