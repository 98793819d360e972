// SPDX-License-Identifier: MIT
#include "audit/firmware_estimates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>
#include <vector>

namespace hrg::audit {

namespace {

constexpr const char* kFeedthroughParts[4] = {"x_re", "x_im", "y_re", "y_im"};

// One group of header keys: absent altogether, or every key a finite number.
class HeaderKeys {
 public:
  HeaderKeys(const recording::Recording& rec, std::string source)
      : rec_(rec), source_(std::move(source)) {}

  bool any(std::span<const std::string> keys) const {
    return std::any_of(keys.begin(), keys.end(),
                       [&](const std::string& k) { return !rec_.metadata_value(k).empty(); });
  }

  // The key's value; `min`: the smallest it may be.
  double number(const std::string& key, double min = -HUGE_VAL) const {
    const std::string text = rec_.metadata_value(key);
    if (text.empty()) fail(key, "is missing (the other keys of its group are there)");
    double v = 0.0;
    bool not_finite = false;
    if (!recording::parse_number(text, v, not_finite))
      fail(key, "= '" + text + "' is not a number");
    if (!(v >= min)) fail(key, "= '" + text + "' is below its smallest value");
    return v;
  }

  // A count (a whole number, at least `min`).
  long count(const std::string& key, long min) const {
    const double v = number(key, static_cast<double>(min));
    if (v != std::floor(v) || v > 1e9) {
      fail(key, "= '" + rec_.metadata_value(key) + "' is not a whole number");
    }
    return static_cast<long>(v);
  }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error(source_ + ": header key '" + key + "' " + what +
                             "; the firmware's estimates are not used");
  }
  const recording::Recording& rec_;
  std::string source_;
};

std::vector<std::string> feedthrough_keys() {
  std::vector<std::string> k{"pump_edge_edges", "pump_edge_sigma_v_per_v",
                             "pump_edge_scatter_v_per_v", "pump_edge_in_force_s"};
  for (const char* p : kFeedthroughParts) {
    k.push_back(std::string("pump_edge_") + p + "_v_per_v");
    k.push_back(std::string("pump_edge_in_force_") + p + "_v_per_v");
  }
  return k;
}

std::optional<FirmwareFeedthrough> read_feedthrough(const HeaderKeys& h) {
  if (!h.any(feedthrough_keys())) return std::nullopt;
  FirmwareFeedthrough f;
  f.edges = h.count("pump_edge_edges", 1);
  f.check_sigma_v_per_v = h.number("pump_edge_sigma_v_per_v", 1e-300);
  f.scatter_v_per_v = h.number("pump_edge_scatter_v_per_v", 0.0);
  f.in_force_s = h.number("pump_edge_in_force_s", 0.0);
  for (std::size_t i = 0; i < 4; ++i) {
    const std::string p = kFeedthroughParts[i];
    // The check reads a residual on top of the feedthrough it saw removed.
    f.total_v_per_v[i] =
        h.number("pump_edge_in_force_" + p + "_v_per_v") + h.number("pump_edge_" + p + "_v_per_v");
  }
  // Edges that scatter more than their noise says: the scatter is the sigma.
  f.sigma_v_per_v = std::max(f.check_sigma_v_per_v, f.scatter_v_per_v);
  return f;
}

std::optional<FirmwareThermalDamping> read_thermal_damping(const HeaderKeys& h) {
  const std::string keys[] = {"damping_check_thermal_damping_per_c",
                              "damping_check_thermal_damping_sigma_per_c"};
  if (!h.any(keys)) return std::nullopt;
  return FirmwareThermalDamping{h.number(keys[0]), h.number(keys[1], 1e-300)};
}

// Each part's value key and its sigma's, and the value's smallest (a gain
// of -1 or below has no inverse).
struct PickoffKeys {
  const char* value;
  const char* sigma;
  double min;
};
constexpr PickoffKeys kPickoffKeys[3] = {
    {"self_cal_gain", "self_cal_gain_sigma", -1.0 + 1e-12},
    {"self_cal_misalignment_rad", "self_cal_misalignment_sigma_rad", -HUGE_VAL},
    {"self_cal_phase_rad", "self_cal_phase_sigma_rad", -HUGE_VAL}};

std::optional<FirmwarePickoffMap> read_pickoff(const HeaderKeys& h) {
  std::vector<std::string> keys;
  for (const PickoffKeys& k : kPickoffKeys) {
    keys.emplace_back(k.value);
    keys.emplace_back(k.sigma);
  }
  if (!h.any(keys)) return std::nullopt;
  FirmwarePickoffPart parts[3];
  for (std::size_t i = 0; i < 3; ++i) {
    parts[i] = {h.number(kPickoffKeys[i].value, kPickoffKeys[i].min),
                h.number(kPickoffKeys[i].sigma, 1e-300)};
  }
  return FirmwarePickoffMap{parts[0], parts[1], parts[2]};
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string values(std::span<const double> v, double sigma, const std::string& unit) {
  std::string s = v.size() > 1 ? "(" : "";
  for (std::size_t i = 0; i < v.size(); ++i)
    s += (i ? ", " : "") + fmt("%.6g", v[i]);
  return s + (v.size() > 1 ? ")" : "") + " +- " + fmt("%.2g", sigma) + " " + unit;
}

}  // namespace

FirmwareEstimates firmware_estimates(const recording::Recording& rec, const std::string& source) {
  const HeaderKeys h(rec, source);
  return {read_feedthrough(h), read_thermal_damping(h), read_pickoff(h)};
}

CombinedEstimate combine_estimates(std::span<const double> audit, double sigma_audit,
                                   std::span<const double> firmware, double sigma_firmware) {
  if (audit.size() != firmware.size() || audit.size() > 4 || !(sigma_audit > 0.0) ||
      !(sigma_firmware > 0.0)) {
    throw std::invalid_argument("combine_estimates: parts or sigmas do not match");
  }
  CombinedEstimate c;
  const double gap_sigma = std::hypot(sigma_audit, sigma_firmware);
  for (std::size_t i = 0; i < audit.size(); ++i) {
    c.disagreement_sigmas =
        std::max(c.disagreement_sigmas, std::fabs(audit[i] - firmware[i]) / gap_sigma);
  }
  if (c.disagreement_sigmas > kMaxDisagreementSigmas) {
    // One of them is wrong beyond its noise: an average would be wrong too.
    const bool fw = sigma_firmware < sigma_audit;
    c.by = fw ? CombinedBy::firmware_alone : CombinedBy::audit_alone;
    c.sigma = fw ? sigma_firmware : sigma_audit;
    std::copy(fw ? firmware.begin() : audit.begin(), fw ? firmware.end() : audit.end(),
              c.value.begin());
    return c;
  }
  const double wa = 1.0 / (sigma_audit * sigma_audit);
  const double wf = 1.0 / (sigma_firmware * sigma_firmware);
  for (std::size_t i = 0; i < audit.size(); ++i)
    c.value[i] = (wa * audit[i] + wf * firmware[i]) / (wa + wf);
  c.sigma = 1.0 / std::sqrt(wa + wf);
  return c;
}

std::string describe_combination(const std::string& what, std::span<const double> audit,
                                 double sigma_audit, std::span<const double> firmware,
                                 double sigma_firmware, const CombinedEstimate& c,
                                 const std::string& unit) {
  const std::string both = "the audit's " + values(audit, sigma_audit, unit) + ", the firmware's " +
                           values(firmware, sigma_firmware, unit);
  const std::string apart = fmt("%.1f sigma apart", c.disagreement_sigmas);
  switch (c.by) {
    case CombinedBy::weighted:
      return what + ": weighted by inverse variance (" + apart + ", within " +
             fmt("%.0f", kMaxDisagreementSigmas) + "): " + both + " -> " +
             values(std::span(c.value.data(), audit.size()), c.sigma, unit);
    case CombinedBy::audit_alone:
    case CombinedBy::firmware_alone:
      return what + ": the " + (c.by == CombinedBy::audit_alone ? "audit's" : "firmware's") +
             " alone, the more precise (" + apart + ", more than " +
             fmt("%.0f", kMaxDisagreementSigmas) + ": one of them is wrong, not averaged): " + both;
  }
  return what;
}

}  // namespace hrg::audit
