// Whole-token number parsing for the log parser: std::from_chars in the C
// locale, with strtod's treatment of a leading '+' and of overflow.
#include "log_number.h"

#include <charconv>
#include <cmath>
#include <system_error>

namespace carmen {
namespace lex {

bool token_to_double(const char *b, const char *e, double &v) {
  if (b < e && *b == '+') {
    ++b;
    if (b < e && (*b == '-' || *b == '+')) return false;
  }
  auto r = std::from_chars(b, e, v);
  if (r.ptr != e || b == e) return false;
  if (r.ec == std::errc()) return true;
  if (r.ec != std::errc::result_out_of_range) return false;
  const bool neg = *b == '-';
  bool neg_exp = false;
  for (const char *q = b; q < e; ++q) {
    if (*q == 'e' || *q == 'E') {
      neg_exp = q + 1 < e && q[1] == '-';
      break;
    }
  }
  v = neg_exp ? (neg ? -0.0 : 0.0) : (neg ? -HUGE_VAL : HUGE_VAL);
  return true;
}

bool token_to_long(const char *b, const char *e, long long &v) {
  if (b < e && *b == '+') {
    ++b;
    if (b < e && (*b == '-' || *b == '+')) return false;
  }
  auto r = std::from_chars(b, e, v);
  if (b == e || r.ptr != e) return false;
  if (r.ec == std::errc::result_out_of_range) {
    v = *b == '-' ? INT64_MIN : INT64_MAX;
    return true;
  }
  return r.ec == std::errc();
}

bool token_is_number(std::string_view t) {
  double v;
  return token_to_double(t.data(), t.data() + t.size(), v);
}

}  // namespace lex
}  // namespace carmen
