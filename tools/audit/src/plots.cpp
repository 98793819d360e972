// SPDX-License-Identifier: MIT
#include "audit/plots.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace hrg::audit {

std::string write_plots(const PlotData& p, const AuditResult& r, const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  const fs::path csv = fs::path(dir) / "audit_blocks.csv";
  {
    std::ofstream f(csv);
    f << "t_s,segment,theta_deg,a_meas_v,a_before_v,a_after_v,q_meas_v,q_before_v,q_after_v,"
         "res_before,res_after\n";
    for (std::size_t i = 0; i < p.t_s.size(); ++i) {
      f << p.t_s[i] << ',' << p.segment[i] << ',' << p.theta_deg[i] << ',' << p.a_meas[i] << ','
        << p.a_before[i] << ',' << p.a_after[i] << ',' << p.q_meas[i] << ',' << p.q_before[i] << ','
        << p.q_after[i] << ',' << p.res_before[i] << ',' << p.res_after[i] << '\n';
    }
    if (!f) return "plots: cannot write " + csv.string();
  }
  std::string title = r.verdict;
  for (const auto& fi : r.findings)
    title += std::string(" ") + effect_info(fi.effect).id;
  const std::string script = std::string(HRG_AUDIT_SCRIPT_DIR) + "/plot_audit.py";
  const std::string cmd =
      "/usr/bin/python3 '" + script + "' '" + csv.string() + "' '" + dir + "' '" + title + "' 2>&1";
  const int rc = std::system(cmd.c_str());
  if (rc != 0) return "plots: data in " + csv.string() + ", but the plot script failed";
  return "plots: " + dir + "/residual_map.png, " + dir + "/fit_before_after.png";
}

}  // namespace hrg::audit
