// SPDX-License-Identifier: MIT
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "can/dbc.hpp"
#include "firmware/can/firmware_estimates.hpp"
#include "hal/can.hpp"

namespace hrg::can {

// Puts the pages of HRG_CAL_READINGS back together (firmware/can/README.md):
// a set is pages 0 to the DBC multiplexor's largest (9; 6 before protocol
// 5) in order with consecutive `seq`; a page out of
// turn or a lost frame drops the set being read (never mixed with another).
// The last complete set is the firmware's readings; none when the log has
// no complete set (nothing is guessed from a partial one).
class CalReadingsReader {
 public:
  // `m` is the DBC's HRG_CAL_READINGS. Throws std::runtime_error when a
  // page's value is outside its signal's DBC range, naming the message, the
  // signal and `where` (the log's file and line).
  void add(const DbcMessage& m, const hal::CanFrame& f, const std::string& where);
  const std::optional<fw::can::FirmwareEstimates>& last() const { return last_; }
  uint64_t complete_sets() const { return complete_; }
  uint64_t dropped_sets() const { return dropped_; }

 private:
  void drop();
  static fw::can::FirmwareEstimates estimates(const std::map<std::string, double>& v);

  int next_page_ = 0;  // the page the set being read needs next (0: none begun)
  int64_t last_seq_ = -1;
  std::map<std::string, double> values_;  // the set being read, by signal name
  std::optional<fw::can::FirmwareEstimates> last_;
  uint64_t complete_ = 0;
  uint64_t dropped_ = 0;
};

}  // namespace hrg::can
