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
#include "log_short_decimal.h"

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

  // n numbers parsed as double and stored as float (the hot loop): block by
  // block while the line has 64 bytes and more left (log_short_decimal.h),
  // and token by token where a block has no short decimal to convert first.
  bool floats(float *out, int n, const char *what) {
    const char *q = p_;
    int i = 0;
    while (i < n) {
      const int got = lex::kBlockParsing && end_ - q >= lex::kBlock + 8 ? block_floats(q, out + i, n - i) : 0;
      if (got > 0) {
        i += got;
        continue;
      }
      if (!one_float(q, out[i], i, what)) return false;
      ++i;
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
  // Converts the short decimals among the tokens that end within the 64 bytes
  // at q (q at a separator), in order and up to `want` of them, stopping
  // before any other token. Moves q to the end of the last one converted;
  // returns how many. q must have 72 bytes readable.
  static int block_floats(const char *&q, float *out, int want) {
    const lex::BlockMasks m = lex::block_masks(q);
    const int clean = m.other ? __builtin_ctzll(m.other) : lex::kBlock;  // bytes before any other
    uint64_t starts = ~m.sep & ~(~m.sep << 1);  // a token's first byte
    uint64_t ends = m.sep & (~m.sep << 1);      // the separator after a token
    int got = 0, last_end = 0;
    while (got < want && ends != 0) {
      const int s = __builtin_ctzll(starts), e = __builtin_ctzll(ends);
      double v;
      if (e > clean || !lex::block_decimal(q + s, e - s, m.dot >> s, v)) break;
      out[got++] = static_cast<float>(v);
      last_end = e;
      starts &= starts - 1;
      ends &= ends - 1;
    }
    q += last_end;
    return got;
  }

  // The i-th of floats()'s numbers at q, by fast_double or else the whole
  // token (which records a failure as field i).
  bool one_float(const char *&q, float &out, int i, const char *what) {
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
    out = static_cast<float>(v);
    return true;
  }

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
