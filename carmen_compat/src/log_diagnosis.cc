// Diagnosis of a bad log line. See log_diagnosis.h.
#include "log_diagnosis.h"

#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "log_number.h"

namespace carmen {

namespace {

using lex::is_sep;
using lex::token_is_number;
using lex::token_to_long;

std::string quote_token(std::string_view t) {
  std::string s = "'";
  const std::size_t kMax = 40;
  for (std::size_t i = 0; i < t.size() && i < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(t[i]);
    if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      s += hex;
    } else {
      s += static_cast<char>(c);
    }
  }
  if (t.size() > kMax) s += "...";
  s += "'";
  return s;
}

std::vector<std::string_view> split_fields(const char *b, const char *e) {
  std::vector<std::string_view> out;
  while (b < e) {
    while (b < e && is_sep(*b)) ++b;
    if (b == e) break;
    const char *s = b;
    while (b < e && !is_sep(*b)) ++b;
    out.emplace_back(s, static_cast<std::size_t>(b - s));
  }
  return out;
}

// A line that stops in the middle has a number, not the host name, as its
// second-to-last field.
bool looks_cut(const std::vector<std::string_view> &t) {
  return t.size() < 2 || token_is_number(t[t.size() - 2]);
}

std::string fields_str(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " field" : " fields");
}

// Records the verdict on a failed line.
void set_error(LineError *err, BadLine kind, std::string message) {
  err->kind = kind;
  err->message = std::move(message);
}

// Step 1: a count that is negative, absurd or not an integer; true when it recorded a verdict.
bool diagnose_count(const std::string &name, const FieldParser &f, LineError *err) {
  if (f.failure == FieldParser::NEGATIVE_COUNT || f.failure == FieldParser::HUGE_COUNT) {
    set_error(err, BadLine::BAD_COUNT,
              name + " " + f.what + " " + std::to_string(f.count_value_) +
                  (f.failure == FieldParser::NEGATIVE_COUNT
                       ? " is negative"
                       : " exceeds the limit of " + std::to_string(kMaxCount)));
    return true;
  }
  const bool count_field = f.what && std::strcmp(f.what, "num_readings") == 0;
  if (f.failure == FieldParser::NOT_NUMBER && count_field) {
    set_error(err, BadLine::NOT_A_NUMBER,
              name + " num_readings (field " + std::to_string(f.failed_field) +
                  "): " + quote_token(f.failed_token) + " is not an integer");
    return true;
  }
  return false;
}

// Compares the line's field count with the `expected` one; records why they differ and returns
// false when they do.
bool check_field_total(std::size_t expected, const std::string &what_needs,
                       const std::vector<std::string_view> &t, const Counts &c, LineError *err) {
  const std::size_t T = t.size();
  if (T == expected) return true;
  if (T < expected && (c.beams < 0 || looks_cut(t))) {
    set_error(err, BadLine::TRUNCATED,
              "truncated line: " + what_needs + " needs " + fields_str(expected) +
                  " after the name, the line has " + std::to_string(T));
  } else if (c.beams >= 0) {
    set_error(err, BadLine::FIELD_COUNT,
              "num_readings " + std::to_string(c.beams) +
                  " disagrees with the fields present: " + what_needs + " needs " +
                  fields_str(expected) + " after the name, the line has " + std::to_string(T));
  } else {
    set_error(err, BadLine::FIELD_COUNT,
              "extra fields: " + what_needs + " has " + fields_str(expected) +
                  " after the name, the line has " + std::to_string(T));
  }
  return false;
}

// Which beam and remission counts would fit a RAWLASERn / ROBOTLASERn line (a hint for the
// message; "" when none does).
std::string beam_count_fit(const std::vector<std::string_view> &t, std::size_t tail) {
  const std::size_t T = t.size();
  for (std::size_t k = 0; 9 + k + tail <= T; ++k) {
    long long rr;
    const std::string_view tok = t[8 + k];
    if (token_to_long(tok.data(), tok.data() + tok.size(), rr) && rr >= 0 &&
        9 + k + static_cast<std::size_t>(rr) + tail == T) {
      return " (the fields fit " + std::to_string(k) + " beams and " + std::to_string(rr) +
             " remissions)";
    }
  }
  return std::string();
}

// Step 2 for RAWLASERn / ROBOTLASERn, whose remission count sits after the beams; true when it
// recorded a verdict.
bool diagnose_raw_structure(const std::string &name, std::size_t tail,
                            const std::vector<std::string_view> &t, const Counts &c,
                            LineError *err) {
  if (c.beams < 0) return false;
  const std::size_t T = t.size();
  const std::size_t rpos = 8 + static_cast<std::size_t>(c.beams);
  long long r = 0;
  const bool have_r = rpos < T && token_to_long(t[rpos].data(), t[rpos].data() + t[rpos].size(), r) &&
                      r >= 0 && r <= kMaxCount;
  const std::size_t expected = rpos + 1 + static_cast<std::size_t>(have_r ? r : 0) + tail;
  if (have_r && T == expected) return false;
  if (T < expected && looks_cut(t)) {
    set_error(err, BadLine::TRUNCATED,
              "truncated line: " + name + " with " + std::to_string(c.beams) +
                  " beams needs at least " + fields_str(expected) +
                  " after the name, the line has " + std::to_string(T));
    return true;
  }
  set_error(err, BadLine::FIELD_COUNT,
            "num_readings " + std::to_string(c.beams) +
                " disagrees with the fields present: the line has " + std::to_string(T) +
                " fields after the name" + beam_count_fit(t, tail));
  return true;
}

// Step 2: the number of fields the rule calls for; true when it recorded a verdict.
bool diagnose_structure(const std::string &name, const FieldRule &rule,
                        const std::vector<std::string_view> &t, const Counts &c, LineError *err) {
  switch (rule.kind) {
    case FieldRule::FIXED:
      return !check_field_total(static_cast<std::size_t>(rule.fields), name, t, c, err);
    case FieldRule::AT_LEAST:
      if (t.size() >= static_cast<std::size_t>(rule.fields)) return false;
      set_error(err, BadLine::TRUNCATED, "truncated line: " + name + " needs " + rule.needs);
      return true;
    case FieldRule::BEAMS:
      return c.beams >= 0 &&
             !check_field_total(static_cast<std::size_t>(rule.fields) + static_cast<std::size_t>(c.beams),
                                name + " with " + std::to_string(c.beams) + " beams", t, c, err);
    case FieldRule::BEAMS_REMISSIONS:
      return diagnose_raw_structure(name, static_cast<std::size_t>(rule.fields), t, c, err);
  }
  return false;
}

// Step 3: the field that tripped the sequential parse.
void diagnose_field(const std::string &name, const FieldParser &f, LineError *err) {
  std::string field = std::string(f.what ? f.what : "field");
  if (f.index >= 0) field += "[" + std::to_string(f.index) + "]";
  field += " (field " + std::to_string(f.failed_field) + ")";
  switch (f.failure) {
    case FieldParser::NOT_NUMBER:
      set_error(err, BadLine::NOT_A_NUMBER,
                name + " " + field + ": " + quote_token(f.failed_token) + " is not a number");
      return;
    case FieldParser::NOT_FINITE:
      set_error(err, BadLine::NON_FINITE,
                name + " " + field + ": " + quote_token(f.failed_token) + " is not finite");
      return;
    case FieldParser::EXTRA:
      set_error(err, BadLine::FIELD_COUNT,
                name + ": extra fields after the logger timestamp, starting with " +
                    quote_token(f.failed_token));
      return;
    case FieldParser::MISSING:
    default:
      set_error(err, BadLine::TRUNCATED, "truncated line: " + name + " ends before its " + field);
      return;
  }
}

}  // namespace

void diagnose(const char *name_text, const FieldRule &rule, const char *begin, const char *end,
              const FieldParser &f, const Counts &c, LineError *err) {
  if (!err) return;
  const std::string name = name_text;
  if (diagnose_count(name, f, err)) return;
  const std::vector<std::string_view> t = split_fields(begin, end);
  if (diagnose_structure(name, rule, t, c, err)) return;
  diagnose_field(name, f, err);
}

}  // namespace carmen
