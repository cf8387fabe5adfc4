// Number lexing for the log parser (internal to carmen_compat): the hot
// fast paths, inline so the field loop keeps them in registers, and the
// whole-token fallbacks in log_number.cc.
#ifndef CARMEN_COMPAT_SRC_LOG_NUMBER_H
#define CARMEN_COMPAT_SRC_LOG_NUMBER_H

#include <cstdint>
#include <cstring>
#include <string_view>

namespace carmen {
namespace lex {

// Fields are separated by spaces and tabs.
inline bool is_sep(char c) { return c == ' ' || c == '\t'; }

// Exactly representable powers of ten.
constexpr double kPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                               1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                               1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// A byte in each of the eight bytes of a word.
constexpr uint64_t kOnes = 0x0101010101010101ull;

// The digit at byte i of w, 8 bytes of a token loaded with p[i] in byte i.
inline unsigned word_digit(uint64_t w, int i) { return static_cast<unsigned>(w >> (8 * i)) & 0x0Fu; }

// The values of the three shapes most ranges take, their bytes loaded in w as
// above: m / 10^f, one division of exact doubles, as fast_double and strtod
// give it. two_decimals and the block parser (log_short_decimal.h) both use
// them.
inline double value_d_dd(uint64_t w) {
  return static_cast<double>(word_digit(w, 0) * 100 + word_digit(w, 2) * 10 + word_digit(w, 3)) / kPow10[2];
}
inline double value_dd_dd(uint64_t w) {
  return static_cast<double>(word_digit(w, 0) * 1000 + word_digit(w, 1) * 100 + word_digit(w, 3) * 10 +
                             word_digit(w, 4)) /
         kPow10[2];
}
inline double value_d_d(uint64_t w) {
  return static_cast<double>(word_digit(w, 0) * 10 + word_digit(w, 2)) / kPow10[1];
}

// The shapes ranges are mostly written in (printf's "%.2f" below 100 m, or
// "%g"): one or two digits, '.', two digits (or one), then a separator. They
// are checked and converted from one 8-byte load: a branch on the shape
// predicts well, where the byte loops of fast_double mispredict at each change
// of length (and took a third of a parse). p must have 8 readable bytes.
// Returns the end of the token, or nullptr for any other shape; the value is
// fast_double's (m / 10^f).
inline const char *two_decimals(const char *p, double &out) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  uint64_t w;
  std::memcpy(&w, p, 8);  // p[i] in byte i
  // 0x80 in each byte that is an ASCII digit (on 7-bit values no carry
  // crosses into the next byte).
  const uint64_t low7 = w & (kOnes * 0x7F);
  const uint64_t digits =
      (low7 + kOnes * (0x80 - '0')) & ~(low7 + kOnes * (0x7F - '9')) & ~w & (kOnes * 0x80);
  // Digits at the bytes of digit_bits, '.' at byte dot, a separator at byte end.
  auto shape = [&](uint64_t digit_bits, int dot, int end) {
    return (digits & digit_bits) == digit_bits && ((w >> (8 * dot)) & 0xFF) == '.' &&
           is_sep(static_cast<char>(w >> (8 * end)));
  };
  if (shape(0x80800080ull, 1, 4)) {  // d.dd
    out = value_d_dd(w);
    return p + 4;
  }
  if (shape(0x8080008080ull, 2, 5)) {  // dd.dd
    out = value_dd_dd(w);
    return p + 5;
  }
  if (shape(0x800080ull, 1, 3)) {  // d.d
    out = value_d_d(w);
    return p + 3;
  }
#else
  (void)p;
  (void)out;
#endif
  return nullptr;
}

// Fast path for the plain decimals logs are made of ("-12.345", "81.91",
// "6.2e-05"): when the digits form an integer m <= 2^53 and the decimal
// exponent e satisfies |e| <= 22, m and 10^|e| are exact doubles and one IEEE
// multiplication or division gives the correctly rounded value (Clinger's
// fast path), bit-identical to strtod and std::from_chars. Returns the end of
// the token, or nullptr when the token needs the general parser (or is not a
// number at all).
inline const char *fast_double(const char *p, const char *end, double &out) {
  bool neg = false;
  if (p < end && *p == '-') {
    neg = true;
    ++p;
  }
  if (end - p >= 8) {
    double v;
    if (const char *r = two_decimals(p, v)) {
      out = neg ? -v : v;
      return r;
    }
  }
  uint64_t m = 0;
  const char *d0 = p;
  while (p < end && static_cast<unsigned>(*p - '0') < 10u) {
    m = m * 10 + static_cast<unsigned>(*p - '0');
    ++p;
  }
  int nd = static_cast<int>(p - d0);
  int exp10 = 0;
  if (p < end && *p == '.') {
    ++p;
    const char *f0 = p;
    while (p < end && static_cast<unsigned>(*p - '0') < 10u) {
      m = m * 10 + static_cast<unsigned>(*p - '0');
      ++p;
    }
    exp10 = -static_cast<int>(p - f0);
    nd -= exp10;
  }
  if (nd == 0 || nd > 19) return nullptr;
  if (p < end && (*p == 'e' || *p == 'E')) {
    ++p;
    bool eneg = false;
    if (p < end && (*p == '-' || *p == '+')) {
      eneg = *p == '-';
      ++p;
    }
    const char *e0 = p;
    int e = 0;
    while (p < end && static_cast<unsigned>(*p - '0') < 10u && p - e0 < 4) {
      e = e * 10 + (*p - '0');
      ++p;
    }
    if (p == e0 || (p < end && static_cast<unsigned>(*p - '0') < 10u)) return nullptr;
    exp10 += eneg ? -e : e;
  }
  if (p < end && !is_sep(*p)) return nullptr;
  if (m > (uint64_t(1) << 53) || exp10 < -22 || exp10 > 22) return nullptr;
  double v = static_cast<double>(m);
  v = exp10 < 0 ? v / kPow10[-exp10] : v * kPow10[exp10];
  out = neg ? -v : v;
  return p;
}

// Whole-token number in the C locale. Accepts what strtod accepts in practice
// (a leading '+', nan, inf); an out-of-range value becomes +-inf or +-0 as
// strtod would make it.
bool token_to_double(const char *b, const char *e, double &v);
// Whole-token integer; out of range saturates to INT64_MIN / INT64_MAX.
bool token_to_long(const char *b, const char *e, long long &v);
bool token_is_number(std::string_view t);

}  // namespace lex
}  // namespace carmen

#endif  // CARMEN_COMPAT_SRC_LOG_NUMBER_H
