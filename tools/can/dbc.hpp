// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hal/can.hpp"

namespace hrg::can {

// The parts of a DBC file the project uses: messages (BO_), signals (SG_, Intel
// byte order; simple multiplexing: one multiplexor `M` per message and
// signals `mN` present when it reads N), cycle times (BA_ "GenMsgCycleTime")
// and value tables (VAL_). Other sections are skipped.
struct DbcSignal {
  std::string name;
  unsigned start_bit = 0;
  unsigned length = 0;
  bool is_signed = false;
  double factor = 1;
  double offset = 0;
  double min = 0;
  double max = 0;
  std::string unit;
  std::map<int64_t, std::string> values;  // VAL_ table
  bool multiplexor = false;               // `M`: its raw value selects the page
  std::optional<unsigned> mux_value;      // `mN`: present only on page N
  std::size_t line = 0;                   // where the DBC defines it (1-based)

  int64_t decode_raw(const hal::CanFrame& f) const;
  double decode(const hal::CanFrame& f) const {
    return static_cast<double>(decode_raw(f)) * factor + offset;
  }
};

struct DbcMessage {
  uint32_t id = 0;
  bool extended = false;
  std::string name;
  unsigned dlc = 0;
  std::string sender;
  std::vector<DbcSignal> signals;
  std::optional<unsigned> cycle_time_ms;  // GenMsgCycleTime, absent for event messages

  const DbcSignal* signal(std::string_view name) const;
  // The multiplexor signal, or nullptr (a plain message).
  const DbcSignal* multiplexor() const;
  // Whether `s` (one of this message's signals) is in frame `f`: always,
  // unless it is multiplexed and the multiplexor reads another page.
  bool present(const DbcSignal& s, const hal::CanFrame& f) const;
};

// Malformed DBC input; `line` is 1-based.
class DbcError : public std::runtime_error {
 public:
  DbcError(const std::string& source, std::size_t line, const std::string& what);
};

struct Dbc {
  unsigned bitrate_bps = 0;  // BS_ (0 when not given)
  std::vector<DbcMessage> messages;

  const DbcMessage* message(uint32_t id) const;
  const DbcMessage* message(std::string_view name) const;
};

// Parses DBC text; `source` names it in errors. Throws DbcError.
Dbc parse_dbc(std::string_view text, const std::string& source = "<dbc>");
// Reads and parses a file. Throws DbcError (or std::runtime_error if unreadable).
Dbc load_dbc(const std::string& path);

}  // namespace hrg::can
