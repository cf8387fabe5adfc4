// The field grammar's primitives (internal to carmen_compat): a sequential
// parser over one line's fields that stops at the first failure and records
// what failed, for the diagnosis (log_diagnosis.h). Inline: it is the hot loop.
#ifndef CARMEN_COMPAT_SRC_LOG_FIELDS_H
#define CARMEN_COMPAT_SRC_LOG_FIELDS_H

#include <cmath>
#include <cstdint>
#include <string_view>

#include "carmen_compat/log_reader.h"
#include "log_number.h"

namespace carmen {

// Sequential field parser. Every method returns false on the first failure and
// records what failed; the caller then diagnoses the line as a whole.
class FieldParser {
 public:
  enum Failure { NONE, MISSING, NOT_NUMBER, NOT_FINITE, NEGATIVE_COUNT, HUGE_COUNT, EXTRA };

  FieldParser(const char *begin, const char *end) : p_(begin), end_(end) {}

  bool number(double &v, const char *what, int index = -1) {
    const char *q = p_;
    while (q < end_ && lex::is_sep(*q)) ++q;
    if (q == end_) return fail(MISSING, what, index, q, q);
    const char *r = lex::fast_double(q, end_, v);
    if (!r) {
      r = q;
      while (r < end_ && !lex::is_sep(*r)) ++r;
      if (!lex::token_to_double(q, r, v)) return fail(NOT_NUMBER, what, index, q, r);
    }
    p_ = r;
    ++field_;
    return true;
  }

  bool finite(double &v, const char *what, int index = -1) {
    const char *start = p_;
    while (start < end_ && lex::is_sep(*start)) ++start;
    if (!number(v, what, index)) return false;
    if (!std::isfinite(v)) {
      --field_;
      return fail(NOT_FINITE, what, index, start, p_);
    }
    return true;
  }

  bool integer(long long &v, const char *what) {
    const char *q = p_;
    while (q < end_ && lex::is_sep(*q)) ++q;
    if (q == end_) return fail(MISSING, what, -1, q, q);
    const char *e = q;
    while (e < end_ && !lex::is_sep(*e)) ++e;
    if (!lex::token_to_long(q, e, v)) return fail(NOT_NUMBER, what, -1, q, e);
    p_ = e;
    ++field_;
    return true;
  }

  bool small_int(int &v, const char *what) {
    long long x;
    const char *start = p_;
    while (start < end_ && lex::is_sep(*start)) ++start;
    if (!integer(x, what)) return false;
    if (x < INT32_MIN || x > INT32_MAX) {
      --field_;
      return fail(NOT_NUMBER, what, -1, start, p_);
    }
    v = static_cast<int>(x);
    return true;
  }

  bool count(int &n, const char *what) {
    long long x;
    const char *start = p_;
    while (start < end_ && lex::is_sep(*start)) ++start;
    if (!integer(x, what)) return false;
    if (x < 0 || x > kMaxCount) {
      --field_;
      count_value_ = x;
      return fail(x < 0 ? NEGATIVE_COUNT : HUGE_COUNT, what, -1, start, p_);
    }
    n = static_cast<int>(x);
    return true;
  }

  // n numbers parsed as double and stored as float (the hot loop).
  bool floats(float *out, int n, const char *what) {
    const char *q = p_;
    for (int i = 0; i < n; ++i) {
      while (q < end_ && lex::is_sep(*q)) ++q;
      double v;
      const char *r = lex::fast_double(q, end_, v);
      if (__builtin_expect(r == nullptr, 0)) {
        p_ = q;
        field_ += i;
        if (!number(v, what, i)) return false;
        q = p_;
        field_ -= i + 1;
      } else {
        q = r;
      }
      out[i] = static_cast<float>(v);
    }
    p_ = q;
    field_ += n;
    return true;
  }

  bool token(const char *&b, const char *&e, const char *what) {
    const char *q = p_;
    while (q < end_ && lex::is_sep(*q)) ++q;
    if (q == end_) return fail(MISSING, what, -1, q, q);
    b = q;
    while (q < end_ && !lex::is_sep(*q)) ++q;
    e = q;
    p_ = q;
    ++field_;
    return true;
  }

  bool at_end() {
    const char *q = p_;
    while (q < end_ && lex::is_sep(*q)) ++q;
    if (q != end_) {
      const char *e = q;
      while (e < end_ && !lex::is_sep(*e)) ++e;
      return fail(EXTRA, "end of line", -1, q, e);
    }
    return true;
  }

  // Fields consumed so far (after the message name).
  int field() const { return field_; }
  const char *pos() const { return p_; }

  Failure failure = NONE;
  const char *what = nullptr;
  int index = -1;
  int failed_field = 0;  // 1-based, among the fields after the name
  std::string_view failed_token;
  long long count_value_ = 0;

 private:
  bool fail(Failure f, const char *w, int i, const char *b, const char *e) {
    failure = f;
    what = w;
    index = i;
    failed_field = field_ + 1;
    failed_token = std::string_view(b, static_cast<std::size_t>(e - b));
    return false;
  }

  const char *p_;
  const char *end_;
  int field_ = 0;
};

// The counts a message announced before it failed (for the diagnosis).
struct Counts {
  int beams = -1;
};

}  // namespace carmen

#endif  // CARMEN_COMPAT_SRC_LOG_FIELDS_H
