// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <string_view>

namespace hrg::sim_run {

// A small streaming JSON writer for report.json: objects, arrays, numbers,
// strings, booleans. Non-finite numbers are written as null (JSON has no NaN).
class JsonWriter {
 public:
  void begin_object(std::string_view key = {});
  void end_object();
  void begin_array(std::string_view key = {});
  void end_array();
  void number(std::string_view key, double v);
  void integer(std::string_view key, long long v);
  void string(std::string_view key, std::string_view v);
  void boolean(std::string_view key, bool v);
  // Array elements.
  void number(double v) { number({}, v); }

  const std::string& str() const { return out_; }

 private:
  void prefix(std::string_view key);
  static std::string escape(std::string_view s);

  std::string out_;
  int depth_ = 0;
  bool first_ = true;
};

}  // namespace hrg::sim_run
