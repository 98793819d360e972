// SPDX-License-Identifier: MIT
#include "can/can_decode.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "can/cal_readings.hpp"
#include "can/candump_log.hpp"
#include "can/dbc.hpp"
#include "can/estimates_header.hpp"
#include "firmware/can/signal.hpp"
#include "recording/recording_writer.hpp"

namespace hrg::can {

namespace {

// Signals read from the log, looked up once in the DBC.
struct Layout {
  const DbcMessage* wave_x;
  const DbcMessage* wave_y;
  const DbcMessage* row;
  const DbcMessage* reference;
  const DbcMessage* loops;
  const DbcMessage* status;
  const DbcMessage* info;
  const DbcMessage* lab_table;
  const DbcMessage* cal_readings;  // nullptr in a DBC before protocol 3
  const DbcMessage* est_quality;
  // The compensation's health (HRG_STATUS.comp_reasons,
  // HRG_EST_QUALITY.readout_damping_sigmas): false in a DBC before protocol 4.
  bool health;
};

bool has_health(const DbcMessage& status, const DbcMessage* quality) {
  return status.signal("comp_reasons") != nullptr && quality != nullptr &&
         quality->signal("readout_damping_sigmas") != nullptr;
}

const DbcMessage& need(const Dbc& dbc, std::string_view name, const std::string& path) {
  const DbcMessage* m = dbc.message(name);
  if (m == nullptr) throw std::runtime_error(path + ": no message " + std::string(name));
  return *m;
}

double value(const DbcMessage& m, std::string_view sig, const hal::CanFrame& f) {
  const DbcSignal* s = m.signal(sig);
  if (s == nullptr)
    throw std::runtime_error("DBC message " + m.name + " has no signal " + std::string(sig));
  return s->decode(f);
}

template <class Fn>
void for_each_frame(const std::string& path, Fn fn) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open CAN log '" + path + "'");
  CandumpLogReader reader(in);
  LoggedFrame lf;
  try {
    while (reader.next(lf))
      fn(lf, reader.line_number());
  } catch (const CandumpError& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

// The DBC message a logged frame is, or nullptr (error and remote frames,
// unknown identifiers, a wrong length or identifier format).
const DbcMessage* known_message(const Dbc& dbc, const LoggedFrame& lf) {
  const DbcMessage* m = lf.error_frame || lf.remote ? nullptr : dbc.message(lf.frame.id);
  if (m == nullptr || m->extended != lf.frame.extended || lf.frame.len != m->dlc) return nullptr;
  return m;
}

// Sequence-counter bookkeeping of one message.
void count_frame(const DbcMessage& m, const hal::CanFrame& f, std::map<uint32_t, int>& last_seq,
                 MessageLosses& ml) {
  ++ml.frames;
  const DbcSignal* seq = m.signal("seq");
  if (seq == nullptr) return;
  const int s = static_cast<int>(seq->decode_raw(f));
  const auto it = last_seq.find(m.id);
  if (it != last_seq.end()) ml.lost += static_cast<uint64_t>((s - it->second - 1 + 256) % 256);
  last_seq[m.id] = s;
}

// Pass 1: metadata (K, reference frequency), the first timestamp and the
// losses per message (from each message's sequence counter).
void scan_log(const CanDecodeOptions& o, const Dbc& dbc, const Layout& L, CanDecodeSummary& sum) {
  std::map<uint32_t, int> last_seq;
  std::optional<double> k = o.angular_gain;
  std::optional<double> f_ref = o.f_ref_hz;
  CalReadingsReader readings;
  for_each_frame(o.log_path, [&](const LoggedFrame& lf, std::size_t line) {
    if (sum.frames++ == 0) sum.t0_s = static_cast<double>(lf.t_ns) * 1e-9;
    sum.span_s = static_cast<double>(lf.t_ns) * 1e-9 - sum.t0_s;
    if (!lf.error_frame) sum.bus_bits += fw::can::worst_case_frame_bits(lf.frame.len);
    const DbcMessage* m = known_message(dbc, lf);
    if (m == nullptr) {
      ++sum.unknown_frames;
      return;
    }
    count_frame(*m, lf.frame, last_seq, sum.messages[m->name]);
    if (m == L.info && !k) k = value(*m, "angular_gain", lf.frame);
    if (m == L.reference && !f_ref) f_ref = value(*m, "f_ref_hz", lf.frame);
    if (m == L.lab_table) sum.has_lab_table = true;
    if (m == L.cal_readings) readings.add(*m, lf.frame, o.log_path + ":" + std::to_string(line));
  });
  sum.estimates = readings.last();
  sum.cal_readings_sets = readings.complete_sets();
  sum.cal_readings_dropped = readings.dropped_sets();
  if (!k)
    throw std::runtime_error(o.log_path +
                             ": no HRG_INFO frame gives angular_gain; pass --angular-gain");
  if (!f_ref) {
    throw std::runtime_error(o.log_path +
                             ": no HRG_REFERENCE frame gives the reference frequency of the "
                             "envelopes (a firmware of protocol 2 sends it each second); pass "
                             "--f-ref-hz");
  }
  sum.angular_gain = *k;
  sum.f_ref_hz = *f_ref;
}

std::vector<std::pair<std::string, std::string>> recording_metadata(const CanDecodeOptions& o,
                                                                    const std::string& dbc_path,
                                                                    const CanDecodeSummary& sum) {
  std::vector<std::pair<std::string, std::string>> meta;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", sum.t0_s);
  meta.emplace_back("source", "CAN log " + o.log_path + " decoded with " + dbc_path);
  meta.emplace_back("can_log_t0_s", buf);
  for (const auto& [name, ml] : sum.messages) {
    meta.emplace_back("can_lost_" + name,
                      std::to_string(ml.lost) + " of " + std::to_string(ml.frames + ml.lost));
  }
  // The firmware's own readings for hrg audit --calibration, from the last
  // complete set of HRG_CAL_READINGS: the keys hrg sim writes.
  if (sum.estimates) {
    for (auto& kv : estimates_header(*sum.estimates))
      meta.push_back(std::move(kv));
  }
  return meta;
}

// The parts of one recording row as they arrive: HRG_WAVE_X, HRG_WAVE_Y and
// HRG_ROW of the same seq, in that order within a base frame.
struct PendingRow {
  int parts = 0;  // 1 after WAVE_X, 2 after WAVE_Y
  int seq = 0;
  double cx = 0, sx = 0, exc_cmd = 0, cy = 0, sy = 0;
};

// The slower messages' latest values.
struct Latest {
  double temp_c = 0, mode = 0, pll_hz = 0, rate_dps = 0;
  double comp_valid = 0, comp_reasons = 0, readout_damping_sigmas = 0;
};

void take_latest(const Layout& L, const DbcMessage* m, const hal::CanFrame& f, bool lab_temp,
                 Latest& v) {
  if (m == L.status) {
    if (!lab_temp) v.temp_c = value(*m, "temp_c", f);
    v.mode = value(*m, "mode", f);
    if (L.health) {
      v.comp_valid = value(*m, "comp_valid", f);
      v.comp_reasons = value(*m, "comp_reasons", f);
    }
  }
  if (m == L.est_quality && L.health)
    v.readout_damping_sigmas = value(*m, "readout_damping_sigmas", f);
  if (m == L.loops) v.pll_hz = value(*m, "pll_freq_hz", f);
  if (m == L.lab_table) {
    v.rate_dps = value(*m, "rate_dps", f);
    v.temp_c = value(*m, "temp_c", f);
  }
}

// A wave or row frame into the pending row; true when the row is complete.
bool take_row_part(const Layout& L, const DbcMessage* m, const hal::CanFrame& f, PendingRow& p,
                   uint64_t& unpaired) {
  const int seq = static_cast<int>(value(*m, "seq", f));
  if (m == L.wave_x) {
    if (p.parts != 0) ++unpaired;
    p = PendingRow{1, seq, value(*m, "cx_v", f), value(*m, "sx_v", f), value(*m, "exc", f)};
    return false;
  }
  const int want = m == L.wave_y ? 1 : 2;
  if (p.parts != want || seq != p.seq) {
    ++unpaired;
    p.parts = 0;
    return false;
  }
  if (m == L.wave_y) {
    p.cy = value(*m, "cy_v", f);
    p.sy = value(*m, "sy_v", f);
    p.parts = 2;
    return false;
  }
  p.parts = 0;
  return true;
}

// Pass 2: rows. The row's time is the firmware's (HRG_ROW.t_s), never the
// log's: the envelopes are against ph = 2 pi f_ref t at exactly that time.
void write_rows(const CanDecodeOptions& o, const Dbc& dbc, const Layout& L,
                recording::RecordingWriter& writer, CanDecodeSummary& sum) {
  PendingRow p;
  Latest v;
  double last_t = -1;
  for_each_frame(o.log_path, [&](const LoggedFrame& lf, std::size_t) {
    const DbcMessage* m = known_message(dbc, lf);
    if (m == nullptr) return;
    const hal::CanFrame& f = lf.frame;
    take_latest(L, m, f, sum.has_lab_table, v);
    if (m != L.wave_x && m != L.wave_y && m != L.row) return;
    if (!take_row_part(L, m, f, p, sum.unpaired_wave)) return;
    const double t = value(*m, "t_s", f);
    if (t <= last_t) {  // not after the previous row: cannot order it
      ++sum.unpaired_wave;
      return;
    }
    last_t = t;
    std::vector<double> row = {
        t,        p.cx,   p.sx,      p.cy,    p.sy, value(*m, "exc", f), value(*m, "pump_v", f),
        v.temp_c, v.mode, p.exc_cmd, v.pll_hz};
    if (sum.has_lab_table) row.push_back(v.rate_dps);
    if (L.health) row.insert(row.end(), {v.comp_valid, v.comp_reasons, v.readout_damping_sigmas});
    writer.write_row(row);
    ++sum.rows;
  });
}

}  // namespace

CanDecodeSummary can_decode(const CanDecodeOptions& o) {
  const std::string dbc_path = o.dbc_path.empty() ? std::string(HRG_DEFAULT_DBC) : o.dbc_path;
  const Dbc dbc = load_dbc(dbc_path);
  const DbcMessage& status = need(dbc, "HRG_STATUS", dbc_path);
  const DbcMessage* quality = dbc.message("HRG_EST_QUALITY");
  const Layout L{&need(dbc, "HRG_WAVE_X", dbc_path), &need(dbc, "HRG_WAVE_Y", dbc_path),
                 &need(dbc, "HRG_ROW", dbc_path),    &need(dbc, "HRG_REFERENCE", dbc_path),
                 &need(dbc, "HRG_LOOPS", dbc_path),  &status,
                 &need(dbc, "HRG_INFO", dbc_path),   dbc.message("LAB_TABLE"),
                 dbc.message("HRG_CAL_READINGS"),    quality,
                 has_health(status, quality)};
  CanDecodeSummary sum;
  sum.bitrate_bps = dbc.bitrate_bps;
  scan_log(o, dbc, L, sum);
  std::vector<std::string> columns = {"t_s",    "cx_v",   "sx_v", "cy_v",    "sy_v",  "exc",
                                      "pump_v", "temp_c", "mode", "exc_cmd", "pll_hz"};
  if (sum.has_lab_table) columns.emplace_back("rate_dps");
  // The columns hrg sim's telemetry.csv gives them.
  if (L.health)
    columns.insert(columns.end(), {"comp_valid", "comp_reasons", "readout_damping_sigmas"});
  recording::RecordingWriter writer(o.out_path, columns, sum.f_ref_hz, sum.angular_gain,
                                    recording_metadata(o, dbc_path, sum));
  write_rows(o, dbc, L, writer, sum);
  writer.close();
  return sum;
}

// What a decode found: rows, losses per message, frames left aside, the bus load.
void print_summary(const CanDecodeOptions& o, const CanDecodeSummary& s) {
  std::printf("can-decode: %llu frames, %llu rows -> %s (f_ref %.5f Hz, K %.5f)\n",
              static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(s.rows),
              o.out_path.c_str(), s.f_ref_hz, s.angular_gain);
  uint64_t lost = 0;
  for (const auto& [name, ml] : s.messages) {
    lost += ml.lost;
    if (ml.lost > 0) {
      std::printf("can-decode: %-16s %llu of %llu frames lost\n", name.c_str(),
                  static_cast<unsigned long long>(ml.lost),
                  static_cast<unsigned long long>(ml.frames + ml.lost));
    }
  }
  if (lost == 0) std::printf("can-decode: no frame lost\n");
  if (s.span_s > 0 && s.bitrate_bps > 0) {
    const double bps = s.bus_bits / s.span_s;
    std::printf(
        "can-decode: bus load %.2f %% of %u bit/s (%.0f bit/s at worst-case stuffing "
        "over %.1f s)\n",
        100.0 * bps / s.bitrate_bps, s.bitrate_bps, bps, s.span_s);
  }
  if (s.estimates) {
    std::printf(
        "can-decode: firmware readings from the last of %llu complete HRG_CAL_READINGS "
        "sets (%s%s%s)\n",
        static_cast<unsigned long long>(s.cal_readings_sets),
        s.estimates->feedthrough ? "pump_edge_*" : "no edge",
        s.estimates->thermal_damping ? ", damping_check_*" : "",
        s.estimates->pickoff ? ", self_cal_*" : "");
  } else {
    std::printf(
        "can-decode: no complete HRG_CAL_READINGS set: no pump_edge_*, damping_check_* or "
        "self_cal_* keys\n");
  }
  if (s.cal_readings_dropped > 0) {
    std::printf("can-decode: %llu HRG_CAL_READINGS sets with a page lost or out of turn not used\n",
                static_cast<unsigned long long>(s.cal_readings_dropped));
  }
  if (s.unpaired_wave > 0) {
    std::printf("can-decode: %llu wave frames without their pair (no row)\n",
                static_cast<unsigned long long>(s.unpaired_wave));
  }
  if (s.unknown_frames > 0) {
    std::printf("can-decode: %llu frames not in the DBC ignored\n",
                static_cast<unsigned long long>(s.unknown_frames));
  }
}

int can_decode_main(std::span<char* const> args) {
  CanDecodeOptions o;
  auto usage = [] {
    std::fprintf(stderr,
                 "usage: hrg can-decode LOG -o REC.csv[.gz] [--dbc FILE] [--angular-gain K] "
                 "[--f-ref-hz F]\n"
                 "Turns a candump -l log of HRG telemetry (protocol 2 to 5; a log of an earlier\n"
                 "protocol than the DBC's with that protocol's DBC) into an hrg-recording v1 that\n"
                 "hrg audit reads (envelopes against HRG_REFERENCE, rows at HRG_ROW.t_s, the\n"
                 "drive as applied, rate and temperature from the bench's LAB_TABLE, the\n"
                 "firmware's readings of HRG_CAL_READINGS as header keys, the compensation's\n"
                 "comp_valid, comp_reasons and readout_damping_sigmas), and reports the frames\n"
                 "lost (from each message's sequence counter) and the bus load.\n");
    return 2;
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    const bool has_value = i + 1 < args.size();
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if ((a == "-o" || a == "--output") && has_value) {
      o.out_path = args[++i];
    } else if (a == "--dbc" && has_value) {
      o.dbc_path = args[++i];
    } else if (a == "--angular-gain" && has_value) {
      o.angular_gain = std::atof(args[++i]);
    } else if (a == "--f-ref-hz" && has_value) {
      o.f_ref_hz = std::atof(args[++i]);
    } else if (!a.empty() && a[0] != '-' && o.log_path.empty()) {
      o.log_path = std::string(a);
    } else {
      std::fprintf(stderr, "hrg can-decode: unexpected argument '%s'\n", args[i]);
      return usage();
    }
  }
  if (o.log_path.empty() || o.out_path.empty()) return usage();
  try {
    print_summary(o, can_decode(o));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg can-decode: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace hrg::can
