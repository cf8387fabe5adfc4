// Block-wise range parsing for the log parser (internal to carmen_compat):
// the separators, dots and other bytes of 64 bytes found at once, and short
// decimals converted from one 8-byte load each.
//
// Why: ranges are most of a log's bytes. Parsed one token after another, each
// token's end (and so where the next one starts) waited on its own bytes, and
// branches on its shape mispredicted at each change of length. With the
// token boundaries of a whole block known up front, the tokens of a block are
// independent and the processor converts several at a time.
#ifndef CARMEN_COMPAT_SRC_LOG_SHORT_DECIMAL_H
#define CARMEN_COMPAT_SRC_LOG_SHORT_DECIMAL_H

#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "log_number.h"

namespace carmen {
namespace lex {

constexpr int kBlock = 64;  // bytes whose separators one mask holds

// Bit j of each mask stands for byte p[j] of a block of 64.
struct BlockMasks {
  uint64_t sep;    // ' ' or '\t'
  uint64_t dot;    // '.'
  uint64_t other;  // neither a separator, a '.' nor a digit
};

// Whether FieldParser takes the block path: where the masks are SSE2's and an
// 8-byte load reads a token's bytes in order (little-endian). Elsewhere the
// scalar masks cost more than the per-token path they would replace.
#if defined(__SSE2__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
constexpr bool kBlockParsing = true;
#else
constexpr bool kBlockParsing = false;
#endif

// The masks of the 64 bytes at p (which must be readable).
inline BlockMasks block_masks(const char *p) {
  BlockMasks m{0, 0, 0};
#if defined(__SSE2__)
  const __m128i space = _mm_set1_epi8(' '), tab = _mm_set1_epi8('\t');
  const __m128i dot = _mm_set1_epi8('.'), zero = _mm_set1_epi8('0'), nine = _mm_set1_epi8(9);
  for (int i = 0; i < 4; ++i) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i *>(p + 16 * i));
    const __m128i sep = _mm_or_si128(_mm_cmpeq_epi8(v, space), _mm_cmpeq_epi8(v, tab));
    const __m128i dots = _mm_cmpeq_epi8(v, dot);
    const __m128i d = _mm_sub_epi8(v, zero);  // a digit: 0..9 unsigned
    const __m128i digit = _mm_cmpeq_epi8(_mm_max_epu8(d, nine), nine);
    const auto bits = [i](__m128i x) {
      return static_cast<uint64_t>(static_cast<uint32_t>(_mm_movemask_epi8(x))) << (16 * i);
    };
    m.sep |= bits(sep);
    m.dot |= bits(dots);
    m.other |= bits(_mm_or_si128(_mm_or_si128(sep, dots), digit));
  }
  m.other = ~m.other;
#else
  for (int j = 0; j < kBlock; ++j) {
    const uint64_t bit = uint64_t(1) << j;
    if (is_sep(p[j])) m.sep |= bit;
    else if (p[j] == '.') m.dot |= bit;
    else if (static_cast<unsigned>(p[j] - '0') >= 10u) m.other |= bit;
  }
#endif
  return m;
}

namespace swar {

// The low `bytes` bytes of a word set (bytes <= 7).
inline uint64_t low_bytes(int bytes) { return (uint64_t(1) << (8 * bytes)) - 1; }

// The value of the digits (0..9 per byte) in d, the first in its lowest byte,
// as one decimal number of 8 digits (fast_float's and simdjson's
// multiply-and-shift).
inline uint32_t eight_digits(uint64_t d) {
  d = d * 10 + (d >> 8);
  d = (((d & 0x000000FF000000FFull) * (100 + (1000000ull << 32))) +
       (((d >> 16) & 0x000000FF000000FFull) * (1 + (10000ull << 32)))) >>
      32;
  return static_cast<uint32_t>(d);
}

}  // namespace swar

// The token of len bytes at p, made of digits and '.' only (the caller
// checked that), with 8 bytes readable at p; bit i of dots says whether p[i]
// is the '.'. When it has at most 7 bytes, one '.' at most and a digit
// ("1.65", "81.91", "3.8", "4", ".5"): its value m / 10^f (m its digits, f
// those after the '.'), one correctly rounded division of exact doubles, as
// fast_double and strtod give it. False for any other token.
inline bool block_decimal(const char *p, int len, uint64_t dots, double &out) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  using namespace swar;
  dots &= (uint64_t(1) << len) - 1;
  uint64_t w;
  std::memcpy(&w, p, 8);  // p[i] in byte i
  // printf's "%.2f" and "%g" below 100 m: most ranges, a branch each.
  if (len == 4 && dots == 0x2) {  // d.dd
    out = value_d_dd(w);
    return true;
  }
  if (len == 3 && dots == 0x2) {  // d.d
    out = value_d_d(w);
    return true;
  }
  if (len == 5 && dots == 0x4) {  // dd.dd
    out = value_dd_dd(w);
    return true;
  }
  const int has_dot = dots != 0;
  const int digits = len - has_dot;
  if (len > 7 || (dots & (dots - 1)) != 0 || digits == 0) return false;
  // The digits before the dot (all, when there is none) then those after it,
  // packed together and right-aligned to eight digits with leading zeros.
  const int before = has_dot ? __builtin_ctzll(dots) : len;
  const int after = len - before - has_dot;
  const uint64_t packed =
      (w & low_bytes(before)) | ((((w >> (8 * before)) >> 8) & low_bytes(after)) << (8 * before));
  const uint64_t values = packed - (kOnes * '0' & low_bytes(digits));
  out = static_cast<double>(eight_digits(values << (8 * (8 - digits)))) / kPow10[after];
  return true;
#else
  (void)p;
  (void)len;
  (void)dots;
  (void)out;
  return false;
#endif
}

}  // namespace lex
}  // namespace carmen

#endif  // CARMEN_COMPAT_SRC_LOG_SHORT_DECIMAL_H
