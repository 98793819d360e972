// SPDX-License-Identifier: MIT
#include "can/estimates_header.hpp"

#include "recording/recording.hpp"

namespace hrg::can {

std::vector<std::pair<std::string, std::string>> estimates_header(
    const fw::can::FirmwareEstimates& e) {
  std::vector<std::pair<std::string, std::string>> meta;
  const auto put = [&](const char* key, double v) {
    meta.emplace_back(key, recording::format_number(v));
  };
  if (e.feedthrough) {
    const auto& r = e.feedthrough_residual_v_per_v;
    const auto& k = e.feedthrough_in_force_v_per_v;
    meta.emplace_back("pump_edge_edges", std::to_string(e.edges));
    put("pump_edge_x_re_v_per_v", r.x_re);
    put("pump_edge_x_im_v_per_v", r.x_im);
    put("pump_edge_y_re_v_per_v", r.y_re);
    put("pump_edge_y_im_v_per_v", r.y_im);
    put("pump_edge_sigma_v_per_v", e.feedthrough_sigma_v_per_v);
    put("pump_edge_scatter_v_per_v", e.feedthrough_scatter_v_per_v);
    put("pump_edge_in_force_s", e.in_force_s);
    put("pump_edge_in_force_x_re_v_per_v", k.x_re);
    put("pump_edge_in_force_x_im_v_per_v", k.x_im);
    put("pump_edge_in_force_y_re_v_per_v", k.y_re);
    put("pump_edge_in_force_y_im_v_per_v", k.y_im);
  }
  if (e.thermal_damping) {
    put("damping_check_thermal_damping_per_c", e.thermal_damping_per_c);
    put("damping_check_thermal_damping_sigma_per_c", e.thermal_damping_sigma_per_c);
  }
  if (e.pickoff) {
    put("self_cal_gain", e.pickoff_gain);
    put("self_cal_gain_sigma", e.pickoff_gain_sigma);
    put("self_cal_misalignment_rad", e.pickoff_misalignment_rad);
    put("self_cal_misalignment_sigma_rad", e.pickoff_misalignment_sigma_rad);
    put("self_cal_phase_rad", e.pickoff_phase_rad);
    put("self_cal_phase_sigma_rad", e.pickoff_phase_sigma_rad);
  }
  return meta;
}

}  // namespace hrg::can
