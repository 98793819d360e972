// SPDX-License-Identifier: MIT
#include "can/dbc.hpp"

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace hrg::can {

namespace {

constexpr uint32_t kExtendedFlag = 0x80000000u;  // DBC marks extended ids with bit 31

// A small tokenizer over one statement: identifiers/numbers, quoted strings and
// single punctuation characters.
class Tokens {
 public:
  Tokens(std::string_view s, const std::string& src, std::size_t line)
      : s_(s), src_(src), line_(line) {}

  bool done() {
    skip_space();
    return pos_ >= s_.size();
  }
  std::string next() {
    skip_space();
    if (pos_ >= s_.size()) fail("unexpected end of statement");
    const char c = s_[pos_];
    if (c == '"') {
      const auto end = s_.find('"', pos_ + 1);
      if (end == std::string_view::npos) fail("unterminated string");
      std::string out(s_.substr(pos_ + 1, end - pos_ - 1));
      pos_ = end + 1;
      return out;
    }
    if (is_word(c)) {
      const std::size_t start = pos_;
      while (pos_ < s_.size() && is_word(s_[pos_]))
        ++pos_;
      return std::string(s_.substr(start, pos_ - start));
    }
    ++pos_;
    return std::string(1, c);
  }
  void expect(std::string_view what) {
    const std::string t = next();
    if (t != what) fail("expected '" + std::string(what) + "', found '" + t + "'");
  }
  double number() {
    const std::string t = next();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size() || errno != 0) fail("'" + t + "' is not a number");
    return v;
  }
  uint64_t integer() {
    const std::string t = next();
    uint64_t v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size()) fail("'" + t + "' is not an integer");
    return v;
  }
  [[noreturn]] void fail(const std::string& what) const { throw DbcError(src_, line_, what); }
  std::size_t line() const { return line_; }

 private:
  static bool is_word(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '.' || c == '-' || c == '+';
  }
  void skip_space() {
    while (pos_ < s_.size() &&
           (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\r' || s_[pos_] == '\n'))
      ++pos_;
  }
  std::string_view s_;
  const std::string& src_;
  std::size_t line_;
  std::size_t pos_ = 0;
};

void parse_signal(Tokens& t, DbcMessage& m) {
  DbcSignal s;
  s.line = t.line();
  s.name = t.next();
  std::string tok = t.next();
  // Simple multiplexing: "M" the multiplexor, "mN" a signal of page N.
  if (tok == "M") {
    s.multiplexor = true;
    tok = t.next();
  } else if (tok.size() > 1 && tok[0] == 'm') {
    unsigned page = 0;
    const auto r = std::from_chars(tok.data() + 1, tok.data() + tok.size(), page);
    if (r.ec != std::errc() || r.ptr != tok.data() + tok.size()) {
      t.fail("signal '" + s.name + "': '" + tok +
             "' is not a multiplex indicator (M or mN; extended multiplexing is not supported)");
    }
    s.mux_value = page;
    tok = t.next();
  }
  if (tok != ":") t.fail("signal '" + s.name + "': expected ':', found '" + tok + "'");
  // "0|24@1-": start, '|', length, '@', then byte order and sign as one word.
  const uint64_t start = t.integer();
  t.expect("|");
  const uint64_t length = t.integer();
  if (start > 63 || length == 0 || length > 64 || start + length > 64)
    t.fail("signal '" + s.name + "' does not fit in 8 bytes");
  s.start_bit = static_cast<unsigned>(start);
  s.length = static_cast<unsigned>(length);
  t.expect("@");
  const std::string order_sign = t.next();
  if (order_sign.size() != 2 || (order_sign[1] != '+' && order_sign[1] != '-'))
    t.fail("signal '" + s.name + "': expected byte order and sign like 1+");
  if (order_sign[0] != '1')
    t.fail("signal '" + s.name + "': only Intel byte order (@1) is supported");
  s.is_signed = order_sign[1] == '-';
  t.expect("(");
  s.factor = t.number();
  t.expect(",");
  s.offset = t.number();
  t.expect(")");
  t.expect("[");
  s.min = t.number();
  t.expect("|");
  s.max = t.number();
  t.expect("]");
  s.unit = t.next();
  if (s.factor == 0) t.fail("signal '" + s.name + "' has a zero factor");
  if (m.signal(s.name) != nullptr) t.fail("signal '" + s.name + "' defined twice");
  if (s.multiplexor && m.multiplexor() != nullptr)
    t.fail("message '" + m.name + "' has a second multiplexor '" + s.name + "'");
  m.signals.push_back(std::move(s));
}

// Every multiplexed signal needs its message's multiplexor.
void check_multiplexing(const Dbc& dbc, const std::string& source) {
  for (const auto& m : dbc.messages) {
    if (m.multiplexor() != nullptr) continue;
    for (const auto& s : m.signals) {
      if (s.mux_value) {
        throw DbcError(source, s.line,
                       "signal '" + s.name + "' of message '" + m.name +
                           "' is multiplexed but the message has no multiplexor (M)");
      }
    }
  }
}

}  // namespace

int64_t DbcSignal::decode_raw(const hal::CanFrame& f) const {
  uint64_t raw = 0;
  for (unsigned i = 0; i < length; ++i) {
    const unsigned bit = start_bit + i;
    raw |= static_cast<uint64_t>((f.data[bit / 8] >> (bit % 8)) & 1u) << i;
  }
  if (is_signed && length < 64 && ((raw >> (length - 1)) & 1u)) {
    return static_cast<int64_t>(raw | (~uint64_t{0} << length));
  }
  return static_cast<int64_t>(raw);
}

const DbcSignal* DbcMessage::signal(std::string_view n) const {
  for (const auto& s : signals)
    if (s.name == n) return &s;
  return nullptr;
}

const DbcSignal* DbcMessage::multiplexor() const {
  for (const auto& s : signals)
    if (s.multiplexor) return &s;
  return nullptr;
}

bool DbcMessage::present(const DbcSignal& s, const hal::CanFrame& f) const {
  if (!s.mux_value) return true;
  const DbcSignal* mux = multiplexor();
  return mux != nullptr && mux->decode_raw(f) == static_cast<int64_t>(*s.mux_value);
}

DbcError::DbcError(const std::string& source, std::size_t line, const std::string& what)
    : std::runtime_error(source + ":" + std::to_string(line) + ": " + what) {}

const DbcMessage* Dbc::message(uint32_t id) const {
  for (const auto& m : messages)
    if (m.id == id) return &m;
  return nullptr;
}

const DbcMessage* Dbc::message(std::string_view name) const {
  for (const auto& m : messages)
    if (m.name == name) return &m;
  return nullptr;
}

Dbc parse_dbc(std::string_view text, const std::string& source) {
  Dbc dbc;
  DbcMessage* current = nullptr;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    auto end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos) {
      current = nullptr;
      continue;
    }
    Tokens t(line, source, line_no);
    const std::string kw = t.next();
    if (kw == "BO_") {
      DbcMessage m;
      const uint64_t raw_id = t.integer();
      m.extended = (raw_id & kExtendedFlag) != 0;
      m.id = static_cast<uint32_t>(raw_id & ~uint64_t{kExtendedFlag});
      m.name = t.next();
      t.expect(":");
      m.dlc = static_cast<unsigned>(t.integer());
      if (m.dlc > 8) t.fail("message '" + m.name + "' has DLC above 8");
      m.sender = t.next();
      if (dbc.message(m.id) != nullptr)
        t.fail("message id " + std::to_string(m.id) + " defined twice");
      dbc.messages.push_back(std::move(m));
      current = &dbc.messages.back();
    } else if (kw == "SG_") {
      if (current == nullptr) t.fail("SG_ outside a BO_ block");
      parse_signal(t, *current);
    } else if (kw == "BS_") {
      t.expect(":");
      if (!t.done()) dbc.bitrate_bps = static_cast<unsigned>(t.integer());
    } else if (kw == "BA_" && !t.done()) {
      const std::string attr = t.next();
      if (attr != "GenMsgCycleTime") continue;
      t.expect("BO_");
      const auto id = static_cast<uint32_t>(t.integer() & ~uint64_t{kExtendedFlag});
      const double v = t.number();
      DbcMessage* m = nullptr;
      for (auto& mm : dbc.messages)
        if (mm.id == id) m = &mm;
      if (m == nullptr) t.fail("cycle time for unknown message " + std::to_string(id));
      if (v < 0 || v > 65535) t.fail("cycle time out of range");
      m->cycle_time_ms = static_cast<unsigned>(v);
    } else if (kw == "VAL_" && !t.done()) {
      const auto id = static_cast<uint32_t>(t.integer() & ~uint64_t{kExtendedFlag});
      const std::string sig = t.next();
      DbcSignal* s = nullptr;
      for (auto& mm : dbc.messages)
        if (mm.id == id)
          for (auto& ss : mm.signals)
            if (ss.name == sig) s = &ss;
      if (s == nullptr) t.fail("value table for unknown signal " + sig);
      while (true) {
        const std::string v = t.next();
        if (v == ";") break;
        char* e = nullptr;
        const long long key = std::strtoll(v.c_str(), &e, 10);
        if (e != v.c_str() + v.size()) t.fail("value table key '" + v + "' is not an integer");
        s->values[key] = t.next();
      }
    }
    // Other statements (VERSION, NS_, BU_, CM_, BA_DEF_, ...) are not needed.
    // A multi-line CM_ string would confuse the line-based reader: the
    // project's DBC keeps comments on one line.
  }
  check_multiplexing(dbc, source);
  return dbc;
}

Dbc load_dbc(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open DBC file '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_dbc(ss.str(), path);
}

}  // namespace hrg::can
