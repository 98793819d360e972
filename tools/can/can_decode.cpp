// SPDX-License-Identifier: MIT
#include "can/can_decode.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "can/candump_log.hpp"
#include "can/dbc.hpp"
#include "recording/recording_writer.hpp"

namespace hrg::can {

namespace {

// Signals read from the log, looked up once in the DBC.
struct Layout {
  const DbcMessage* wave_x;
  const DbcMessage* wave_y;
  const DbcMessage* loops;
  const DbcMessage* pump;
  const DbcMessage* status;
  const DbcMessage* info;
};

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
      fn(lf);
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

// Pass 1: metadata (K, reference frequency), the first timestamp and the
// losses per message (from each message's sequence counter). Returns the
// first frame's time, ns.
uint64_t scan_log(const CanDecodeOptions& o, const Dbc& dbc, const Layout& L,
                  CanDecodeSummary& sum) {
  std::map<uint32_t, int> last_seq;
  std::optional<double> k = o.angular_gain;
  std::optional<double> f_ref = o.f_ref_hz;
  uint64_t t0_ns = 0;
  for_each_frame(o.log_path, [&](const LoggedFrame& lf) {
    if (sum.frames++ == 0) {
      t0_ns = lf.t_ns;
      sum.t0_s = static_cast<double>(lf.t_ns) * 1e-9;
    }
    const DbcMessage* m = known_message(dbc, lf);
    if (m == nullptr) {
      ++sum.unknown_frames;
      return;
    }
    MessageLosses& ml = sum.messages[m->name];
    ++ml.frames;
    if (const DbcSignal* seq = m->signal("seq")) {
      const int s = static_cast<int>(seq->decode_raw(lf.frame));
      const auto it = last_seq.find(m->id);
      if (it != last_seq.end()) ml.lost += static_cast<uint64_t>((s - it->second - 1 + 256) % 256);
      last_seq[m->id] = s;
    }
    if (m == L.info && !k) k = value(*m, "angular_gain", lf.frame);
    if (m == L.loops && !f_ref) f_ref = value(*m, "pll_freq_hz", lf.frame);
  });
  if (!k)
    throw std::runtime_error(o.log_path +
                             ": no HRG_INFO frame gives angular_gain; pass --angular-gain");
  if (!f_ref)
    throw std::runtime_error(o.log_path +
                             ": no HRG_LOOPS frame gives the reference frequency; pass --f-ref-hz");
  sum.angular_gain = *k;
  sum.f_ref_hz = *f_ref;
  return t0_ns;
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
  return meta;
}

// Pass 2: rows. A WAVE_X waits for the WAVE_Y with the same seq; the slower
// messages give their latest values.
void write_rows(const CanDecodeOptions& o, const Dbc& dbc, const Layout& L, uint64_t t0_ns,
                recording::RecordingWriter& writer, CanDecodeSummary& sum) {
  double pump_v = 0, temp_c = 0, mode = 0, f_row = sum.f_ref_hz;
  bool have_x = false;
  int x_seq = 0;
  double x_t = 0, cx = 0, sx = 0, exc = 0, last_t = -1;
  for_each_frame(o.log_path, [&](const LoggedFrame& lf) {
    const DbcMessage* m = known_message(dbc, lf);
    if (m == nullptr) return;
    const hal::CanFrame& f = lf.frame;
    // Relative time in integer nanoseconds first: epoch seconds in a double
    // would keep only ~0.2 us.
    const double t = static_cast<double>(static_cast<int64_t>(lf.t_ns - t0_ns)) * 1e-9;
    if (m == L.pump) pump_v = value(*m, "pump_v", f);
    if (m == L.status) {
      temp_c = value(*m, "temp_c", f);
      mode = value(*m, "mode", f);
    }
    if (m == L.loops) f_row = value(*m, "pll_freq_hz", f);
    if (m == L.wave_x) {
      if (have_x) ++sum.unpaired_wave;
      have_x = true;
      x_seq = static_cast<int>(value(*m, "seq", f));
      x_t = t;
      cx = value(*m, "cx_v", f);
      sx = value(*m, "sx_v", f);
      exc = value(*m, "exc", f);
    }
    if (m == L.wave_y) {
      if (!have_x || static_cast<int>(value(*m, "seq", f)) != x_seq) {
        ++sum.unpaired_wave;
        have_x = false;
        return;
      }
      have_x = false;
      if (x_t <= last_t) {  // same log timestamp as the previous row: cannot order it
        ++sum.unpaired_wave;
        return;
      }
      last_t = x_t;
      const double row[] = {
          x_t,    cx,    sx,  value(*m, "cy_v", f), value(*m, "sy_v", f), exc, pump_v,
          temp_c, f_row, mode};
      writer.write_row(row);
      ++sum.rows;
    }
  });
}

}  // namespace

CanDecodeSummary can_decode(const CanDecodeOptions& o) {
  const std::string dbc_path = o.dbc_path.empty() ? std::string(HRG_DEFAULT_DBC) : o.dbc_path;
  const Dbc dbc = load_dbc(dbc_path);
  const Layout L{&need(dbc, "HRG_WAVE_X", dbc_path), &need(dbc, "HRG_WAVE_Y", dbc_path),
                 &need(dbc, "HRG_LOOPS", dbc_path),  &need(dbc, "HRG_PUMP", dbc_path),
                 &need(dbc, "HRG_STATUS", dbc_path), &need(dbc, "HRG_INFO", dbc_path)};
  CanDecodeSummary sum;
  const uint64_t t0_ns = scan_log(o, dbc, L, sum);
  recording::RecordingWriter writer(
      o.out_path,
      {"t_s", "cx_v", "sx_v", "cy_v", "sy_v", "exc", "pump_v", "temp_c", "f_ref_hz", "mode"},
      sum.f_ref_hz, sum.angular_gain, recording_metadata(o, dbc_path, sum));
  write_rows(o, dbc, L, t0_ns, writer, sum);
  writer.close();
  return sum;
}

int can_decode_main(std::span<char* const> args) {
  CanDecodeOptions o;
  auto usage = [] {
    std::fprintf(stderr,
                 "usage: hrg can-decode LOG -o REC.csv[.gz] [--dbc FILE] [--angular-gain K] "
                 "[--f-ref-hz F]\n"
                 "Turns a candump -l log of HRG telemetry into an hrg-recording v1 and reports\n"
                 "the frames lost (from each message's sequence counter).\n");
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
    const CanDecodeSummary s = can_decode(o);
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
    if (s.unpaired_wave > 0) {
      std::printf("can-decode: %llu wave frames without their pair (no row)\n",
                  static_cast<unsigned long long>(s.unpaired_wave));
    }
    if (s.unknown_frames > 0) {
      std::printf("can-decode: %llu frames not in the DBC ignored\n",
                  static_cast<unsigned long long>(s.unknown_frames));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hrg can-decode: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace hrg::can
