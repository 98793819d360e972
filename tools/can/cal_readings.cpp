// SPDX-License-Identifier: MIT
#include "can/cal_readings.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace hrg::can {

namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

void CalReadingsReader::drop() {
  if (next_page_ != 0) ++dropped_;
  next_page_ = 0;
  values_.clear();
}

void CalReadingsReader::add(const DbcMessage& m, const hal::CanFrame& f, const std::string& where) {
  const DbcSignal* page_sig = m.multiplexor();
  const DbcSignal* seq_sig = m.signal("seq");
  if (page_sig == nullptr || seq_sig == nullptr)
    throw std::runtime_error("DBC message " + m.name + " has no multiplexor or no seq");
  // Every signal of this page within its DBC range (the multiplexor, first
  // in the message, too: it says which signals are there).
  for (const auto& s : m.signals) {
    if (!m.present(s, f)) continue;
    const double v = s.decode(f);
    const double lsb = 0.5 * std::fabs(s.factor);  // the DBC's decimal ends of a raw field
    if (v < s.min - lsb || v > s.max + lsb) {
      throw std::runtime_error(where + ": " + m.name + " signal '" + s.name + "' = " + number(v) +
                               " is outside its range [" + number(s.min) + ", " + number(s.max) +
                               "]");
    }
  }
  const auto page = static_cast<int>(page_sig->decode_raw(f));
  const int64_t seq = seq_sig->decode_raw(f);
  const bool in_turn = page == 0 || (page == next_page_ && seq == (last_seq_ + 1) % 256);
  if (!in_turn) {
    drop();
    last_seq_ = seq;
    return;
  }
  if (page == 0) drop();
  for (const auto& s : m.signals)
    if (m.present(s, f) && &s != seq_sig && &s != page_sig) values_[s.name] = s.decode(f);
  last_seq_ = seq;
  next_page_ = page + 1;
  // A set is as many pages as the DBC's multiplexor holds: a log of
  // protocol 4 (pages 0-6) decodes with its own DBC.
  if (next_page_ <= static_cast<int>(page_sig->max)) return;
  last_ = estimates(values_);
  ++complete_;
  next_page_ = 0;
  values_.clear();
}

fw::can::FirmwareEstimates CalReadingsReader::estimates(const std::map<std::string, double>& v) {
  fw::can::FirmwareEstimates e;
  const auto at = [&](const char* name) {
    const auto it = v.find(name);
    if (it == v.end())
      throw std::runtime_error(std::string("DBC message HRG_CAL_READINGS has no signal ") + name);
    return it->second;
  };
  e.edges = static_cast<uint32_t>(at("pump_edge_edges"));
  e.feedthrough = e.edges > 0;
  e.in_force_s = at("pump_edge_in_force_s");
  e.feedthrough_residual_v_per_v = {at("pump_edge_x_re_v_per_v"), at("pump_edge_x_im_v_per_v"),
                                    at("pump_edge_y_re_v_per_v"), at("pump_edge_y_im_v_per_v")};
  e.feedthrough_sigma_v_per_v = at("pump_edge_sigma_v_per_v");
  e.feedthrough_scatter_v_per_v = at("pump_edge_scatter_v_per_v");
  e.feedthrough_in_force_v_per_v = {
      at("pump_edge_in_force_x_re_v_per_v"), at("pump_edge_in_force_x_im_v_per_v"),
      at("pump_edge_in_force_y_re_v_per_v"), at("pump_edge_in_force_y_im_v_per_v")};
  e.thermal_damping = at("thermal_valid") != 0.0;
  e.thermal_damping_per_c = at("thermal_damping_per_c");
  e.thermal_damping_sigma_per_c = at("thermal_damping_sigma_per_c");
  // Protocol 5 on: the pickoff self-calibration's map (none before).
  if (v.count("self_cal_valid") == 0) return e;
  e.pickoff = at("self_cal_valid") != 0.0;
  e.pickoff_gain = at("self_cal_gain");
  e.pickoff_gain_sigma = at("self_cal_gain_sigma");
  e.pickoff_misalignment_rad = at("self_cal_misalignment_rad");
  e.pickoff_misalignment_sigma_rad = at("self_cal_misalignment_sigma_rad");
  e.pickoff_phase_rad = at("self_cal_phase_rad");
  e.pickoff_phase_sigma_rad = at("self_cal_phase_sigma_rad");
  return e;
}

}  // namespace hrg::can
