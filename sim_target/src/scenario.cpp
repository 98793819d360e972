// SPDX-License-Identifier: MIT
#include "sim_target/scenario.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <vector>

#include "toml_text/toml_text.hpp"

namespace hrg::sim {

namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Reads one TOML table, remembers the keys it consumed and rejects the rest.
class Section {
 public:
  Section(const toml::table* table, std::string path, const std::string& source)
      : table_(table), path_(std::move(path)), source_(source) {}

  bool present() const { return table_ != nullptr; }
  bool has(const std::string& key) const { return table_ && table_->contains(key); }
  std::string key_name(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
  }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw ScenarioError(source_ + ": key '" + key_name(key) + "': " + what);
  }

  double number(const std::string& key, double lo, double hi, double fallback, const char* unit) {
    if (!has(key)) return fallback;
    used_.insert(key);
    const toml::node& n = *table_->get(key);
    double v = 0.0;
    if (auto d = n.value_exact<double>()) {
      v = *d;
    } else if (auto i = n.value_exact<int64_t>()) {
      v = static_cast<double>(*i);
    } else {
      fail(key, "must be a number");
    }
    check_range(key, v, lo, hi, unit);
    return v;
  }

  uint64_t integer(const std::string& key, int64_t lo, int64_t hi, uint64_t fallback,
                   const char* unit) {
    if (!has(key)) return fallback;
    used_.insert(key);
    auto i = table_->get(key)->value_exact<int64_t>();
    if (!i) fail(key, "must be an integer");
    if (*i < lo || *i > hi) {
      fail(key, std::to_string(*i) + " is out of range [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "]" + (unit[0] ? std::string(" ") + unit : ""));
    }
    return static_cast<uint64_t>(*i);
  }

  bool boolean(const std::string& key, bool fallback) {
    if (!has(key)) return fallback;
    used_.insert(key);
    auto b = table_->get(key)->value_exact<bool>();
    if (!b) fail(key, "must be true or false");
    return *b;
  }

  std::string text(const std::string& key, const std::string& fallback) {
    if (!has(key)) return fallback;
    used_.insert(key);
    auto s = table_->get(key)->value_exact<std::string>();
    if (!s) fail(key, "must be a string");
    return *s;
  }

  std::vector<double> numbers(const std::string& key, double lo, double hi, const char* unit) {
    if (!has(key)) fail(key, "is required here");
    used_.insert(key);
    const toml::array* arr = table_->get(key)->as_array();
    if (!arr || arr->empty()) fail(key, "must be a non-empty array of numbers");
    std::vector<double> out;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const toml::node& n = *arr->get(i);
      double v = 0.0;
      if (auto d = n.value_exact<double>()) {
        v = *d;
      } else if (auto k = n.value_exact<int64_t>()) {
        v = static_cast<double>(*k);
      } else {
        fail(key, "element " + std::to_string(i) + " must be a number");
      }
      check_range(key + "[" + std::to_string(i) + "]", v, lo, hi, unit);
      out.push_back(v);
    }
    return out;
  }

  Section sub(const std::string& key) {
    if (!has(key)) return Section(nullptr, key_name(key), source_);
    used_.insert(key);
    const toml::table* t = table_->get(key)->as_table();
    if (!t) fail(key, "must be a table");
    return Section(t, key_name(key), source_);
  }

  // Rejects every key this section did not read.
  void finish() const {
    if (!table_) return;
    for (const auto& [k, v] : *table_) {
      const std::string key(k.str());
      if (!used_.count(key)) fail(key, "unknown key");
    }
  }

 private:
  void check_range(const std::string& key, double v, double lo, double hi, const char* unit) const {
    if (!std::isfinite(v) || v < lo || v > hi) {
      fail(key, fmt(v) + " is out of range [" + fmt(lo) + ", " + fmt(hi) + "]" +
                    (unit[0] ? std::string(" ") + unit : ""));
    }
  }

  const toml::table* table_;
  std::string path_;
  const std::string& source_;
  std::set<std::string> used_;
};

// A rate or temperature profile. `unit_key` is "dps" or "c"; `scale` converts to SI.
Profile read_profile(Section s, const char* unit_key, double scale, double lo, double hi,
                     double fallback_si, const std::string& base_dir) {
  if (!s.present()) return Profile::constant(fallback_si);
  const std::string unit(unit_key);
  const std::string value_key = "value_" + unit;
  const char* unit_name = unit == "dps" ? "deg/s" : "degC";
  const std::string kind = s.text("kind", "constant");
  Profile p;
  if (kind == "constant") {
    p = Profile::constant(s.number(value_key, lo, hi, fallback_si / scale, unit_name) * scale);
  } else if (kind == "steps" || kind == "ramps") {
    const auto t = s.numbers("t_s", 0.0, 1e9, "s");
    const auto v = s.numbers(value_key, lo, hi, unit_name);
    if (t.size() != v.size()) s.fail(value_key, "must have as many elements as t_s");
    std::vector<ProfilePoint> pts;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (i > 0 && !(t[i] > t[i - 1])) s.fail("t_s", "times must increase strictly");
      pts.push_back({t[i], v[i] * scale});
    }
    p = kind == "steps" ? Profile::steps(pts) : Profile::ramps(pts);
  } else if (kind == "sine") {
    const double amp = s.number("amplitude_" + unit, 0.0, hi - lo, 0.0, unit_name);
    const double f = s.number("freq_hz", 0.0, 1e4, 0.0, "Hz");
    const double ph = s.number("phase_deg", -360.0, 360.0, 0.0, "deg");
    const double mean =
        s.number("mean_" + unit, lo, hi, unit == "c" ? fallback_si : 0.0, unit_name);
    p = Profile::sine(amp * scale, f, ph * kDegToRad);
    p.add_offset(mean * scale);
  } else if (kind == "table") {
    std::filesystem::path file(s.text("file", ""));
    if (file.empty()) s.fail("file", "is required for kind = \"table\"");
    if (file.is_relative()) file = std::filesystem::path(base_dir) / file;
    try {
      p = Profile::table_file(file.string(), scale);
    } catch (const std::exception& e) {
      s.fail("file", e.what());
    }
  } else {
    s.fail("kind", "'" + kind + "' is not one of constant, steps, ramps, sine, table");
  }
  if (unit == "dps") {
    const double lat = s.number("earth_latitude_deg", -90.0, 90.0,
                                std::numeric_limits<double>::quiet_NaN(), "deg");
    if (!std::isnan(lat)) p.add_offset(kEarthRateRadS * std::sin(lat * kDegToRad));
  }
  s.finish();
  return p;
}

void read_effects(Section s, Effects& fx) {
  {
    Section e = s.sub("pickoff_gain_mismatch");
    fx.pickoff_gain_mismatch.enabled = e.boolean("enabled", false);
    fx.pickoff_gain_mismatch.gain = e.number("gain", -0.5, 0.5, 0.0, "");
    e.finish();
  }
  {
    Section e = s.sub("pickoff_phase_mismatch");
    fx.pickoff_phase_mismatch.enabled = e.boolean("enabled", false);
    fx.pickoff_phase_mismatch.phase_deg = e.number("phase_deg", -90.0, 90.0, 0.0, "deg");
    e.finish();
  }
  {
    Section e = s.sub("pickoff_misalignment");
    fx.pickoff_misalignment.enabled = e.boolean("enabled", false);
    fx.pickoff_misalignment.angle_deg = e.number("angle_deg", -45.0, 45.0, 0.0, "deg");
    e.finish();
  }
  {
    Section e = s.sub("duffing_stiffness");
    fx.duffing_stiffness.enabled = e.boolean("enabled", false);
    fx.duffing_stiffness.hz_per_v2 = e.number("hz_per_v2", -10.0, 10.0, 0.0, "Hz/V^2");
    e.finish();
  }
  {
    Section e = s.sub("nonlinear_damping");
    fx.nonlinear_damping.enabled = e.boolean("enabled", false);
    fx.nonlinear_damping.rel_per_v2 = e.number("rel_per_v2", -0.2, 10.0, 0.0, "1/V^2");
    e.finish();
  }
  {
    Section e = s.sub("thermal_frequency");
    fx.thermal_frequency.enabled = e.boolean("enabled", false);
    fx.thermal_frequency.ppm_per_c = e.number("ppm_per_c", -1000.0, 1000.0, 0.0, "ppm/degC");
    e.finish();
  }
  {
    Section e = s.sub("thermal_damping");
    fx.thermal_damping.enabled = e.boolean("enabled", false);
    fx.thermal_damping.rel_per_c = e.number("rel_per_c", -0.005, 0.005, 0.0, "1/degC");
    e.finish();
  }
  {
    Section e = s.sub("electrostatic_spring");
    fx.electrostatic_spring.enabled = e.boolean("enabled", false);
    fx.electrostatic_spring.hz_per_v2 = e.number("hz_per_v2", -1.0, 1.0, 0.0, "Hz/V^2");
    e.finish();
  }
  {
    Section e = s.sub("drive_feedthrough");
    fx.drive_feedthrough.enabled = e.boolean("enabled", false);
    fx.drive_feedthrough.x_v_per_v = e.number("x_v_per_v", -1.0, 1.0, 0.0, "V/V");
    fx.drive_feedthrough.y_v_per_v = e.number("y_v_per_v", -1.0, 1.0, 0.0, "V/V");
    fx.drive_feedthrough.x_phase_deg = e.number("x_phase_deg", -360.0, 360.0, 0.0, "deg");
    fx.drive_feedthrough.y_phase_deg = e.number("y_phase_deg", -360.0, 360.0, 0.0, "deg");
    e.finish();
  }
  s.finish();
}

void read_resonator(Section s, SimConfig& c) {
  auto& r = c.resonator;
  r.f_hz = s.number("f_hz", 1.0, 1e6, r.f_hz, "Hz");
  r.q = s.number("q", 1e2, 1e10, r.q, "");
  r.dmu = s.number("dmu", -0.5, 0.5, r.dmu, "");
  r.th_mu_rad = s.number("th_mu_deg", -180.0, 180.0, r.th_mu_rad / kDegToRad, "deg") * kDegToRad;
  r.split_hz = s.number("split_hz", -10.0, 10.0, r.split_hz, "Hz");
  r.th_w_rad = s.number("th_w_deg", -180.0, 180.0, r.th_w_rad / kDegToRad, "deg") * kDegToRad;
  r.angular_gain = s.number("angular_gain", 0.01, 2.0, r.angular_gain, "");
  r.temp_ref_c = s.number("temp_ref_c", -100.0, 200.0, r.temp_ref_c, "degC");
  s.finish();
}

void read_electrodes(Section s, SimConfig& c) {
  auto& e = c.electrodes;
  e.pump_gain_per_s2_v2 =
      s.number("pump_gain_per_s2_v2", 0.0, 1e6, e.pump_gain_per_s2_v2, "1/(s^2 V^2)");
  e.eps_p = s.number("eps_p", -0.5, 0.5, e.eps_p, "");
  e.eps_q = s.number("eps_q", -0.5, 0.5, e.eps_q, "");
  e.forcer_gain_per_s2 = s.number("forcer_gain_per_s2", 0.0, 1e6, e.forcer_gain_per_s2, "1/s^2");
  s.finish();
}

void read_initial(Section s, SimConfig& c) {
  c.initial.amplitude_v = s.number("amplitude_v", 0.0, 100.0, c.initial.amplitude_v, "V");
  c.initial.theta_rad = s.number("theta_deg", -180.0, 180.0, 0.0, "deg") * kDegToRad;
  c.initial.quad_v = s.number("quad_v", -100.0, 100.0, c.initial.quad_v, "V");
  s.finish();
}

void read_adc(Section s, SimConfig& c) {
  auto& a = c.adc;
  a.sample_rate_hz =
      static_cast<uint32_t>(s.integer("sample_rate_hz", 1000, 10'000'000, a.sample_rate_hz, "Hz"));
  a.block_frames = static_cast<uint32_t>(s.integer("block_frames", 1, 100'000, a.block_frames, ""));
  a.bits = static_cast<uint32_t>(s.integer("bits", 2, 32, a.bits, ""));
  a.full_scale_v = s.number("full_scale_v", 1e-3, 1000.0, a.full_scale_v, "V");
  a.noise_v_rms[0] = s.number("noise_x_v_rms", 0.0, 10.0, a.noise_v_rms[0], "V");
  a.noise_v_rms[1] = s.number("noise_y_v_rms", 0.0, 10.0, a.noise_v_rms[1], "V");
  a.offset_v[0] = s.number("offset_x_v", -10.0, 10.0, a.offset_v[0], "V");
  a.offset_v[1] = s.number("offset_y_v", -10.0, 10.0, a.offset_v[1], "V");
  s.finish();
}

void read_dac(Section s, SimConfig& c) {
  auto& d = c.dac;
  d.bits = static_cast<uint32_t>(s.integer("bits", 2, 32, d.bits, ""));
  d.full_scale_v = s.number("full_scale_v", 1e-3, 1000.0, d.full_scale_v, "V");
  d.latency_samples =
      static_cast<uint32_t>(s.integer("latency_samples", 0, 100'000, d.latency_samples, "samples"));
  s.finish();
}

void read_can(Section s, SimConfig& c) {
  c.can.tx_queue_frames =
      static_cast<uint32_t>(s.integer("tx_queue_frames", 1, 4096, c.can.tx_queue_frames, "frames"));
  c.can.tx_frames_per_ms = static_cast<uint32_t>(
      s.integer("tx_frames_per_ms", 1, 1000, c.can.tx_frames_per_ms, "frames/ms"));
  s.finish();
}

}  // namespace

SimConfig parse_scenario(std::string_view text, const std::string& source,
                         const std::string& base_dir) {
  toml::table root;
  try {
    root = toml_text::parse(text, source,
                            "scenario files are ASCII, comments included (write deg, degC, uV)");
  } catch (const toml_text::TextError& e) {
    throw ScenarioError(e.what());
  }
  SimConfig c;
  Section top(&root, "", source);
  c.seed = top.integer("seed", 0, std::numeric_limits<int64_t>::max(), c.seed, "");
  read_resonator(top.sub("resonator"), c);
  read_electrodes(top.sub("electrodes"), c);
  read_initial(top.sub("initial"), c);
  read_adc(top.sub("adc"), c);
  read_dac(top.sub("dac"), c);
  read_can(top.sub("can"), c);
  c.rate_rad_s = read_profile(top.sub("rate"), "dps", kDegToRad, -1e4, 1e4, 0.0, base_dir);
  c.temp_c = read_profile(top.sub("temperature"), "c", 1.0, -100.0, 200.0, c.resonator.temp_ref_c,
                          base_dir);
  read_effects(top.sub("effects"), c.effects);
  top.finish();
  return c;
}

SimConfig load_scenario(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ScenarioError(path + ": cannot open scenario file");
  std::stringstream text;
  text << in.rdbuf();
  const std::string base = std::filesystem::path(path).parent_path().string();
  return parse_scenario(text.str(), path, base.empty() ? "." : base);
}

}  // namespace hrg::sim
