// SPDX-License-Identifier: MIT
#include "study/grid.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

// As the scenario reader: toml++'s assertions off, so a malformed header is a
// parse error (upstream marzer/tomlplusplus#301) in every build.
#ifndef TOML_ASSERT
#define TOML_ASSERT(expr) static_cast<void>(0)
#endif
#include <toml++/toml.h>

namespace hrg::study {

namespace {

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// One table of the grid file: typed reads that name file:line: key on error,
// and a check that no key was left unread.
class Table {
 public:
  Table(const toml::table& root, const std::string& name, const std::string& source)
      : source_(source), name_(name) {
    const toml::node* n = root.get(name);
    if (n == nullptr) return;
    table_ = n->as_table();
    if (table_ == nullptr) fail(n, "", "must be a table");
  }

  [[noreturn]] void fail(const toml::node* at, const std::string& key,
                         const std::string& what) const {
    const auto line = at != nullptr ? at->source().begin.line : 1;
    const std::string full = key.empty() ? name_ : name_ + "." + key;
    throw GridError(source_ + ":" + std::to_string(line) + ": key '" + full + "': " + what);
  }

  double number(const std::string& key, double lo, double hi, double fallback) {
    const toml::node* n = get(key);
    if (n == nullptr) return fallback;
    return checked(n, key, n, lo, hi);
  }

  int integer(const std::string& key, int64_t lo, int64_t hi, int64_t fallback) {
    const toml::node* n = get(key);
    if (n == nullptr) return static_cast<int>(fallback);
    const auto v = n->value_exact<int64_t>();
    if (!v) fail(n, key, "must be an integer");
    if (*v < lo || *v > hi)
      fail(n, key,
           std::to_string(*v) + " is out of range [" + std::to_string(lo) + ", " +
               std::to_string(hi) + "]");
    return static_cast<int>(*v);
  }

  std::vector<double> numbers(const std::string& key, double lo, double hi) {
    const toml::node* n = get(key);
    if (n == nullptr) fail(table_, key, "is required");
    const toml::array* arr = n->as_array();
    if (arr == nullptr || arr->empty()) fail(n, key, "must be a non-empty array of numbers");
    std::vector<double> out;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const std::string elem = key + "[" + std::to_string(i) + "]";
      out.push_back(checked(arr->get(i), elem, n, lo, hi));
    }
    return out;
  }

  void finish() const {
    if (table_ == nullptr) return;
    for (const auto& [k, v] : *table_) {
      const std::string key(k.str());
      if (used_.count(key) == 0) fail(&v, key, "unknown key");
    }
  }

 private:
  const toml::node* get(const std::string& key) {
    if (table_ == nullptr) {
      if (name_ == "grid") fail(nullptr, "", "the [grid] table is required");
      return nullptr;
    }
    used_.insert(key);
    return table_->get(key);
  }

  double checked(const toml::node* n, const std::string& key, const toml::node* line_of, double lo,
                 double hi) const {
    double v = 0.0;
    if (auto d = n->value_exact<double>()) {
      v = *d;
    } else if (auto i = n->value_exact<int64_t>()) {
      v = static_cast<double>(*i);
    } else {
      fail(line_of, key, "must be a number");
    }
    if (!std::isfinite(v) || v < lo || v > hi)
      fail(line_of, key, num(v) + " is out of range [" + num(lo) + ", " + num(hi) + "]");
    return v;
  }

  std::string source_;
  std::string name_;
  const toml::table* table_ = nullptr;
  std::set<std::string> used_;
};

}  // namespace

Grid parse_grid(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw GridError(source + ":" + std::to_string(e.source().begin.line) + ": " +
                    std::string(e.description()));
  }
  for (const auto& [k, v] : root) {
    const std::string key(k.str());
    if (key != "grid" && key != "run")
      throw GridError(source + ":" + std::to_string(v.source().begin.line) + ": key '" + key +
                      "': unknown table (expected [grid] and [run])");
  }
  Grid g;
  g.source = source;
  Table grid(root, "grid", source);
  g.split_hz = grid.numbers("split_hz", 1e-6, 1.0);
  g.dq_over_q = grid.numbers("dq_over_q", 0.0, 0.9);
  g.gap = grid.numbers("gap", 0.0, 0.2);
  g.q = grid.numbers("q", 1e4, 1e9);
  g.gap_axis_deg = grid.number("gap_axis_deg", -90.0, 90.0, g.gap_axis_deg);
  grid.finish();
  Table run(root, "run", source);
  g.duration_s = run.number("duration_s", 60.0, 7.0 * 86400.0, g.duration_s);
  g.seeds = run.integer("seeds", 1, 100, g.seeds);
  g.base_seed = static_cast<uint64_t>(run.integer("base_seed", 1, 2'000'000'000, 20240531));
  g.bias_angles = run.integer("bias_angles", 4, 64, g.bias_angles);
  g.sample_every_s = run.number("sample_every_s", 0.1, 3600.0, g.sample_every_s);
  run.finish();
  return g;
}

Grid load_grid(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw GridError(path + ":1: cannot open the grid file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_grid(text.str(), path);
}

PointSpec point_spec(const Grid& grid, std::size_t index) {
  PointSpec p;
  p.index = index;
  std::size_t i = index;
  p.split_hz = grid.split_hz[i % grid.split_hz.size()];
  i /= grid.split_hz.size();
  p.dq_over_q = grid.dq_over_q[i % grid.dq_over_q.size()];
  i /= grid.dq_over_q.size();
  p.gap = grid.gap[i % grid.gap.size()];
  i /= grid.gap.size();
  p.q = grid.q[i % grid.q.size()];
  return p;
}

}  // namespace hrg::study
