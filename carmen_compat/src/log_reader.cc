// Streaming CARMEN log reader: buffered read (or inflate, gzip_stream.h), line
// splitting, strict field parsing with std::from_chars, and diagnosis of bad
// lines.
#include "carmen_compat/log_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <memory>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <system_error>

#include "gzip_stream.h"

namespace carmen {

namespace {

// M_PI as CARMEN's headers define it (glibc's value).
constexpr double kPi = 3.14159265358979323846;

inline bool is_sep(char c) { return c == ' ' || c == '\t'; }

const char *const kTypeNames[kNumMessageTypes] = {
    "FLASER",    "RLASER",    "ROBOTLASER1", "ROBOTLASER2", "RAWLASER1", "RAWLASER2",
    "RAWLASER3", "RAWLASER4", "ODOM",        "TRUEPOS",     "PARAM",     "SYNC"};

const char *const kBadLineNames[kNumBadLineClasses] = {
    "truncated", "field count", "not a number", "bad count", "non-finite", "too long"};

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

// Exactly representable powers of ten.
constexpr double kPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                               1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                               1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// The shapes ranges are mostly written in (printf's "%.2f" below 100 m, or
// "%g"): one or two digits, '.', two digits (or one), then a separator. They
// are checked and converted from one 8-byte load: a branch on the shape
// predicts well, where the byte loops of fast_double mispredict at each change
// of length (and took a third of a parse). p must have 8 readable bytes.
// Returns the end of the token, or nullptr for any other shape; the value is
// fast_double's (m / 10^f).
inline const char *two_decimals(const char *p, double &out) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  constexpr uint64_t kOnes = 0x0101010101010101ull;
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
  auto digit = [w](int i) { return static_cast<unsigned>(w >> (8 * i)) & 0x0Fu; };
  if (shape(0x80800080ull, 1, 4)) {  // d.dd
    out = static_cast<double>(digit(0) * 100 + digit(2) * 10 + digit(3)) / kPow10[2];
    return p + 4;
  }
  if (shape(0x8080008080ull, 2, 5)) {  // dd.dd
    out = static_cast<double>(digit(0) * 1000 + digit(1) * 100 + digit(3) * 10 + digit(4)) /
          kPow10[2];
    return p + 5;
  }
  if (shape(0x800080ull, 1, 3)) {  // d.d
    out = static_cast<double>(digit(0) * 10 + digit(2)) / kPow10[1];
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

// ---------------------------------------------------------------------------
// Sequential field parser. Every method returns false on the first failure and
// records what failed; the caller then diagnoses the line as a whole.
class FieldParser {
 public:
  enum Failure { NONE, MISSING, NOT_NUMBER, NOT_FINITE, NEGATIVE_COUNT, HUGE_COUNT, EXTRA };

  FieldParser(const char *begin, const char *end) : p_(begin), end_(end) {}

  bool number(double &v, const char *what, int index = -1) {
    const char *q = p_;
    while (q < end_ && is_sep(*q)) ++q;
    if (q == end_) return fail(MISSING, what, index, q, q);
    const char *r = fast_double(q, end_, v);
    if (!r) {
      r = q;
      while (r < end_ && !is_sep(*r)) ++r;
      if (!token_to_double(q, r, v)) return fail(NOT_NUMBER, what, index, q, r);
    }
    p_ = r;
    ++field_;
    return true;
  }

  bool finite(double &v, const char *what, int index = -1) {
    const char *start = p_;
    while (start < end_ && is_sep(*start)) ++start;
    if (!number(v, what, index)) return false;
    if (!std::isfinite(v)) {
      --field_;
      return fail(NOT_FINITE, what, index, start, p_);
    }
    return true;
  }

  bool integer(long long &v, const char *what) {
    const char *q = p_;
    while (q < end_ && is_sep(*q)) ++q;
    if (q == end_) return fail(MISSING, what, -1, q, q);
    const char *e = q;
    while (e < end_ && !is_sep(*e)) ++e;
    if (!token_to_long(q, e, v)) return fail(NOT_NUMBER, what, -1, q, e);
    p_ = e;
    ++field_;
    return true;
  }

  bool small_int(int &v, const char *what) {
    long long x;
    const char *start = p_;
    while (start < end_ && is_sep(*start)) ++start;
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
    while (start < end_ && is_sep(*start)) ++start;
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
      while (q < end_ && is_sep(*q)) ++q;
      double v;
      const char *r = fast_double(q, end_, v);
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
    while (q < end_ && is_sep(*q)) ++q;
    if (q == end_) return fail(MISSING, what, -1, q, q);
    b = q;
    while (q < end_ && !is_sep(*q)) ++q;
    e = q;
    p_ = q;
    ++field_;
    return true;
  }

  bool at_end() {
    const char *q = p_;
    while (q < end_ && is_sep(*q)) ++q;
    if (q != end_) {
      const char *e = q;
      while (e < end_ && !is_sep(*e)) ++e;
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

bool parse_trailer(FieldParser &f, double &timestamp, std::string &host, double &logger_timestamp,
                   const char **after_host) {
  if (!f.finite(timestamp, "ipc_timestamp")) return false;
  const char *hb, *he;
  if (!f.token(hb, he, "host")) return false;
  host.assign(hb, static_cast<std::size_t>(he - hb));
  if (after_host) *after_host = he;
  if (!f.finite(logger_timestamp, "logger_timestamp")) return false;
  return f.at_end();
}

bool parse_point(FieldParser &f, Point &p, const char *x, const char *y, const char *t) {
  return f.finite(p.x, x) && f.finite(p.y, y) && f.finite(p.theta, t);
}

bool parse_old_laser(FieldParser &f, LaserMessage &m, bool with_poses, Counts &c,
                     const char **after_host) {
  int n;
  if (!f.count(n, "num_readings")) return false;
  c.beams = n;
  m.range.resize(static_cast<std::size_t>(n));
  if (!f.floats(m.range.data(), n, "range")) return false;
  m.remission.clear();
  if (with_poses) {
    if (!parse_point(f, m.laser_pose, "x", "y", "theta")) return false;
    if (!parse_point(f, m.robot_pose, "odom_x", "odom_y", "odom_theta")) return false;
  } else {
    m.laser_pose = Point();
    m.robot_pose = Point();
  }
  if (!parse_trailer(f, m.timestamp, m.host, m.logger_timestamp, after_host)) return false;
  m.id = -1;
  m.config = guess_laser_config(n);
  m.has_pose = with_poses;
  m.tv = m.rv = m.forward_safety_dist = m.side_safety_dist = m.turn_axis = 0;
  return true;
}

bool parse_new_laser(FieldParser &f, LaserMessage &m, bool robot, Counts &c,
                     const char **after_host) {
  LaserConfig &cfg = m.config;
  if (!f.small_int(cfg.laser_type, "laser_type")) return false;
  if (!f.finite(cfg.start_angle, "start_angle")) return false;
  if (!f.finite(cfg.fov, "fov")) return false;
  if (!f.finite(cfg.angular_resolution, "angular_resolution")) return false;
  if (!f.finite(cfg.maximum_range, "maximum_range")) return false;
  if (!f.finite(cfg.accuracy, "accuracy")) return false;
  if (!f.small_int(cfg.remission_mode, "remission_mode")) return false;
  int n;
  if (!f.count(n, "num_readings")) return false;
  c.beams = n;
  m.range.resize(static_cast<std::size_t>(n));
  if (!f.floats(m.range.data(), n, "range")) return false;
  int r;
  if (!f.count(r, "num_remissions")) return false;
  m.remission.resize(static_cast<std::size_t>(r));
  if (!f.floats(m.remission.data(), r, "remission")) return false;
  if (robot) {
    if (!parse_point(f, m.laser_pose, "laser_x", "laser_y", "laser_theta")) return false;
    if (!parse_point(f, m.robot_pose, "robot_x", "robot_y", "robot_theta")) return false;
    if (!f.finite(m.tv, "tv") || !f.finite(m.rv, "rv") ||
        !f.finite(m.forward_safety_dist, "forward_safety_dist") ||
        !f.finite(m.side_safety_dist, "side_safety_dist") || !f.finite(m.turn_axis, "turn_axis"))
      return false;
  } else {
    m.laser_pose = Point();
    m.robot_pose = Point();
    m.tv = m.rv = m.forward_safety_dist = m.side_safety_dist = m.turn_axis = 0;
  }
  m.has_pose = robot;
  return parse_trailer(f, m.timestamp, m.host, m.logger_timestamp, after_host);
}

int type_id(MessageType t) {
  switch (t) {
    case MessageType::ROBOTLASER1: return 1;
    case MessageType::ROBOTLASER2: return 2;
    case MessageType::RAWLASER1: return 1;
    case MessageType::RAWLASER2: return 2;
    case MessageType::RAWLASER3: return 3;
    case MessageType::RAWLASER4: return 4;
    default: return -1;
  }
}

// ---------------------------------------------------------------------------
// Diagnosis of a failed line. Structural problems (too few or too many
// fields for the counts) are reported before the field that tripped the
// sequential parse, since a wrong count makes every later field look wrong.

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
bool diagnose_raw_structure(MessageType type, const std::string &name,
                            const std::vector<std::string_view> &t, const Counts &c,
                            LineError *err) {
  if (c.beams < 0) return false;
  const std::size_t T = t.size();
  const std::size_t tail = (type == MessageType::ROBOTLASER1 ||
                            type == MessageType::ROBOTLASER2) ? 14 : 3;
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

// Step 2: the number of fields the counts call for; true when it recorded a verdict. `poses`:
// FLASER/RLASER lines carry poses (old LASERn lines have none).
bool diagnose_structure(MessageType type, const std::string &name, bool poses,
                        const std::vector<std::string_view> &t, const Counts &c, LineError *err) {
  switch (type) {
    case MessageType::ODOM:
    case MessageType::TRUEPOS:
      return !check_field_total(9, name, t, c, err);
    case MessageType::PARAM:
      if (t.size() >= 2) return false;
      set_error(err, BadLine::TRUNCATED, "truncated line: PARAM needs a name and a value");
      return true;
    case MessageType::SYNC:
      if (t.size() >= 1) return false;
      set_error(err, BadLine::TRUNCATED, "truncated line: SYNC needs a tag");
      return true;
    case MessageType::FLASER:
    case MessageType::RLASER: {
      const std::size_t fixed = poses ? 10 : 4;
      return c.beams >= 0 &&
             !check_field_total(fixed + static_cast<std::size_t>(c.beams),
                                name + " with " + std::to_string(c.beams) + " beams", t, c, err);
    }
    default:  // RAWLASERn / ROBOTLASERn
      return diagnose_raw_structure(type, name, t, c, err);
  }
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

// Explains why `f` failed on the line [begin, end): a bad count first, then the field total,
// then the field itself.
void diagnose(MessageType type, const char *begin, const char *end, const FieldParser &f,
              const Counts &c, LineError *err, const char *name_override = nullptr) {
  if (!err) return;
  const std::string name = name_override ? name_override : message_type_name(type);
  if (diagnose_count(name, f, err)) return;
  const std::vector<std::string_view> t = split_fields(begin, end);
  const bool poses = name_override == nullptr;  // old LASERn lines have none
  if (diagnose_structure(type, name, poses, t, c, err)) return;
  diagnose_field(name, f, err);
}

}  // namespace

// ---------------------------------------------------------------------------
// Names, config guessing, stats.

const char *message_type_name(MessageType type) {
  const int i = static_cast<int>(type);
  return i >= 0 && i < kNumMessageTypes ? kTypeNames[i] : "?";
}

bool message_type_from_name(const char *s, std::size_t n, MessageType *type) {
  MessageType t;
  switch (n) {
    case 4:
      if (std::memcmp(s, "ODOM", 4) == 0) t = MessageType::ODOM;
      else if (std::memcmp(s, "SYNC", 4) == 0) t = MessageType::SYNC;
      else return false;
      break;
    case 5:
      if (std::memcmp(s, "PARAM", 5) != 0) return false;
      t = MessageType::PARAM;
      break;
    case 6:
      if (std::memcmp(s, "FLASER", 6) == 0) t = MessageType::FLASER;
      else if (std::memcmp(s, "RLASER", 6) == 0) t = MessageType::RLASER;
      else return false;
      break;
    case 7:
      if (std::memcmp(s, "TRUEPOS", 7) != 0) return false;
      t = MessageType::TRUEPOS;
      break;
    case 9:
      if (std::memcmp(s, "RAWLASER", 8) != 0 || s[8] < '1' || s[8] > '4') return false;
      t = static_cast<MessageType>(static_cast<int>(MessageType::RAWLASER1) + (s[8] - '1'));
      break;
    case 11:
      if (std::memcmp(s, "ROBOTLASER", 10) != 0 || s[10] < '1' || s[10] > '2') return false;
      t = s[10] == '1' ? MessageType::ROBOTLASER1 : MessageType::ROBOTLASER2;
      break;
    default:
      return false;
  }
  if (type) *type = t;
  return true;
}

bool is_laser_message(MessageType type) {
  return static_cast<int>(type) <= static_cast<int>(MessageType::RAWLASER4);
}

const char *bad_line_name(BadLine kind) {
  const int i = static_cast<int>(kind);
  return i >= 0 && i < kNumBadLineClasses ? kBadLineNames[i] : "?";
}

double guess_laser_fov(int n) {
  if (n == 181) return kPi;
  if (n == 180) return kPi / 180.0 * 179.0;
  if (n == 361) return kPi;
  if (n == 360) return kPi / 180.0 * 179.5;
  if (n == 401) return kPi / 180.0 * 100.0;
  if (n == 400) return kPi / 100.0 * 99.75;
  return kPi;
}

double guess_laser_angle_increment(int n) {
  if (n == 181 || n == 180) return kPi / 180.0;
  if (n == 361 || n == 360) return kPi / 360.0;
  if (n == 401 || n == 400) return kPi / 720.0;
  return guess_laser_fov(n) / static_cast<double>(n - 1);
}

LaserConfig guess_laser_config(int n) {
  LaserConfig c;
  c.laser_type = 0;
  c.start_angle = -kPi / 2.0;
  c.fov = guess_laser_fov(n);
  c.angular_resolution = guess_laser_angle_increment(n);
  c.maximum_range = 80.0;
  c.accuracy = 0.01;
  c.remission_mode = 0;
  return c;
}

uint64_t LogStats::laser_messages() const {
  uint64_t s = 0;
  for (int i = 0; i < kNumMessageTypes; ++i)
    if (is_laser_message(static_cast<MessageType>(i))) s += messages[i];
  return s;
}

uint64_t LogStats::total_messages() const {
  uint64_t s = 0;
  for (uint64_t m : messages) s += m;
  return s;
}

uint64_t LogStats::total_bad_lines() const {
  uint64_t s = 0;
  for (uint64_t b : bad_lines) s += b;
  return s;
}

std::string LogStats::summary() const {
  std::string s = std::to_string(lines) + " lines, " + std::to_string(bytes) + " bytes; messages:";
  bool any = false;
  for (int i = 0; i < kNumMessageTypes; ++i) {
    if (messages[i] == 0) continue;
    s += std::string(any ? ", " : " ") + std::to_string(messages[i]) + " " + kTypeNames[i];
    any = true;
  }
  if (!any) s += " none";
  s += "\nskipped: " + std::to_string(unknown_lines) + " unknown";
  if (!unknown_names.empty()) {
    s += " (";
    for (std::size_t i = 0; i < unknown_names.size(); ++i)
      s += (i ? ", " : "") + unknown_names[i].first + " " + std::to_string(unknown_names[i].second);
    s += ")";
  }
  s += ", " + std::to_string(comment_lines) + " comment, " + std::to_string(blank_lines) + " blank";
  if (nan_ranges || inf_ranges || negative_ranges)
    s += "\nranges: " + std::to_string(nan_ranges) + " NaN, " + std::to_string(inf_ranges) +
         " inf, " + std::to_string(negative_ranges) + " negative";
  if (total_bad_lines()) {
    s += "\nbad lines skipped:";
    bool first = true;
    for (int i = 0; i < kNumBadLineClasses; ++i) {
      if (!bad_lines[i]) continue;
      s += std::string(first ? " " : ", ") + std::to_string(bad_lines[i]) + " " + kBadLineNames[i] +
           " (first at line " + std::to_string(first_bad_line[i]) + ")";
      first = false;
    }
  }
  return s;
}

// ---------------------------------------------------------------------------
// Line parsing.

bool parse_message_fields(MessageType type, const char *begin, const char *end, LogMessage &msg,
                          LineError *err, const char **after_host) {
  FieldParser f(begin, end);
  Counts c;
  bool ok = false;
  msg.type = type;
  switch (type) {
    case MessageType::FLASER:
    case MessageType::RLASER:
      ok = parse_old_laser(f, msg.laser, true, c, after_host);
      break;
    case MessageType::ROBOTLASER1:
    case MessageType::ROBOTLASER2:
      ok = parse_new_laser(f, msg.laser, true, c, after_host);
      msg.laser.id = type_id(type);
      break;
    case MessageType::RAWLASER1:
    case MessageType::RAWLASER2:
    case MessageType::RAWLASER3:
    case MessageType::RAWLASER4:
      ok = parse_new_laser(f, msg.laser, false, c, after_host);
      msg.laser.id = type_id(type);
      break;
    case MessageType::ODOM: {
      OdometryMessage &o = msg.odom;
      ok = f.finite(o.x, "x") && f.finite(o.y, "y") && f.finite(o.theta, "theta") &&
           f.finite(o.tv, "tv") && f.finite(o.rv, "rv") && f.finite(o.acceleration, "accel") &&
           parse_trailer(f, o.timestamp, o.host, o.logger_timestamp, after_host);
      break;
    }
    case MessageType::TRUEPOS: {
      TrueposMessage &t = msg.truepos;
      ok = parse_point(f, t.truepose, "true_x", "true_y", "true_theta") &&
           parse_point(f, t.odometrypose, "odom_x", "odom_y", "odom_theta") &&
           parse_trailer(f, t.timestamp, t.host, t.logger_timestamp, after_host);
      break;
    }
    case MessageType::PARAM: {
      const char *nb, *ne, *vb, *ve;
      ok = f.token(nb, ne, "name") && f.token(vb, ve, "value");
      if (ok) {
        msg.param.name.assign(nb, static_cast<std::size_t>(ne - nb));
        msg.param.value.assign(vb, static_cast<std::size_t>(ve - vb));
      }
      break;
    }
    case MessageType::SYNC: {
      const char *tb, *te;
      ok = f.token(tb, te, "tag");
      if (ok) msg.sync.tag.assign(tb, static_cast<std::size_t>(te - tb));
      break;
    }
  }
  if (!ok) diagnose(type, begin, end, f, c, err);
  return ok;
}

bool parse_old_laser_fields(const char *begin, const char *end, LaserMessage &laser,
                            LineError *err, const char **after_host) {
  FieldParser f(begin, end);
  Counts c;
  if (parse_old_laser(f, laser, false, c, after_host)) return true;
  diagnose(MessageType::FLASER, begin, end, f, c, err, "LASER");
  return false;
}

LineKind parse_log_line(const char *begin, const char *end, LogMessage &msg, LineError *err,
                        const char **name_end) {
  if (end > begin && end[-1] == '\r') --end;
  const char *p = begin;
  while (p < end && is_sep(*p)) ++p;
  if (p == end) return LineKind::BLANK;
  const char *q = p;
  while (q < end && !is_sep(*q)) ++q;
  if (name_end) *name_end = q;
  if (*p == '#') return LineKind::COMMENT;
  MessageType type;
  if (!message_type_from_name(p, static_cast<std::size_t>(q - p), &type)) return LineKind::UNKNOWN;
  return parse_message_fields(type, q, end, msg, err) ? LineKind::MESSAGE : LineKind::BAD;
}

// ---------------------------------------------------------------------------
// The reader.

namespace {

bool ends_with(const std::string &s, const char *suffix) {
  const std::size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

// Whether every range is a finite number >= 0 (-0 included), as nearly all
// are: a test on the bits, which vectorizes where comparing floats one by
// one took a tenth of a parse.
bool all_plain_ranges(const std::vector<float> &r) {
  uint32_t odd = 0;
  for (float v : r) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    odd |= static_cast<uint32_t>(bits >= 0x7F800000u) & static_cast<uint32_t>(bits != 0x80000000u);
  }
  return odd == 0;
}

// Control bytes other than \t \n \v \f \r, and DEL, mark binary data.
inline bool is_binary_byte(unsigned char c) { return c < 9 || (c >= 14 && c < 32) || c == 127; }

const unsigned char *find_binary(const unsigned char *p, const unsigned char *e) {
  while (e - p >= 64) {
    // Byte-wide lanes throughout, so that the loop vectorizes 16 bytes at a
    // time (with unsigned lanes it ran 4 at a time, a tenth of a parse).
    unsigned char acc = 0;
    for (int i = 0; i < 64; ++i) {
      const unsigned char c = p[i];
      acc |= static_cast<unsigned char>(c < 9) |
             static_cast<unsigned char>(static_cast<unsigned char>(c - 14) < 18) |
             static_cast<unsigned char>(c == 127);
    }
    if (acc) break;
    p += 64;
  }
  for (; p < e; ++p)
    if (is_binary_byte(*p)) return p;
  return nullptr;
}

constexpr std::size_t kReadChunk = std::size_t(256) << 10;  // text per refill (stays in L2)
constexpr uint64_t kNoBinary = UINT64_MAX;
constexpr std::size_t kMaxLineCap = std::size_t(1) << 30;  // largest max_line_length honoured

}  // namespace

struct LogReader::Impl {
  std::string path;
  LogReaderOptions opt;
  LogStats stats;

  std::FILE *fp = nullptr;
  uint64_t size = 0;
  uint64_t comp_read = 0;   // plain files; a .gz's count is its inflater's
  bool gzip_magic = false;  // the file starts with 1f 8b
  bool gz = false;
  std::unique_ptr<gzip::BackgroundInflater> inflater;  // gz == true

  // Text buffer: [pos, lim) not yet consumed; buf[0] is stream offset base.
  // Not zero-filled: most of its max_line_length part (4 MiB by default) is
  // never touched, and so never paged in.
  std::unique_ptr<char[]> buf;
  std::size_t buf_size = 0;
  std::size_t pos = 0, lim = 0, scan = 0;
  uint64_t base = 0;
  bool src_eof = false;
  std::string src_error;  // deferred: thrown once the good lines before it are consumed
  uint64_t binary_at = kNoBinary;
  unsigned char binary_byte = 0;
  bool skipping = false;  // lenient: discarding the rest of an over-long line

  long line_no = 0;
  LineError err;

  ~Impl() {
    inflater.reset();  // its thread reads fp
    if (fp) std::fclose(fp);
  }

  [[noreturn]] void fail(long line, const std::string &m) const { throw FileError(path, line, m); }

  void open() {
    struct stat pst;
    if (stat(path.c_str(), &pst) == 0 && S_ISDIR(pst.st_mode))
      fail(0, "is a directory, not a log file");
    fp = std::fopen(path.c_str(), "rb");
    if (!fp) fail(0, std::string("cannot open: ") + std::strerror(errno));
    struct stat st;
    if (fstat(fileno(fp), &st) != 0) fail(0, std::string("cannot stat: ") + std::strerror(errno));
    if (S_ISDIR(st.st_mode)) fail(0, "is a directory, not a log file");
    size = static_cast<uint64_t>(st.st_size);
    unsigned char magic[2] = {0, 0};
    const std::size_t got = std::fread(magic, 1, 2, fp);
    if (std::ferror(fp)) fail(0, std::string("read error: ") + std::strerror(errno));
    if (got == 0) fail(0, "empty file");
    gzip_magic = got == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
    if (std::fseek(fp, 0, SEEK_SET) != 0) fail(0, "cannot rewind the file");
    // As zlib's gzread: a .gz name with non-gzip content is read as it is.
    gz = ends_with(path, ".gz") && gzip_magic;
    if (gz) {
      try {
        inflater = std::make_unique<gzip::BackgroundInflater>(fp, kReadChunk);
      } catch (const std::exception &e) {
        fail(0, std::string("cannot start inflating: ") + e.what());
      }
    }
    opt.max_line_length = std::min(std::max(opt.max_line_length, std::size_t(16)), kMaxLineCap);
    buf_size = opt.max_line_length + kReadChunk + 1;
    buf.reset(new char[buf_size]);
  }

  std::size_t read_plain(char *dst, std::size_t cap) {
    const std::size_t n = std::fread(dst, 1, cap, fp);
    comp_read += n;
    if (n < cap) {
      if (std::ferror(fp)) src_error = std::string("read error: ") + std::strerror(errno);
      else src_eof = true;
    }
    return n;
  }

  std::size_t read_gz(char *dst, std::size_t cap) {
    std::size_t n = 0;
    while (n < cap) {
      bool eof = false;
      std::string error;
      const std::size_t got = inflater->read(dst + n, cap - n, &eof, &error);
      n += got;
      if (got == 0) {
        if (!error.empty()) src_error = error;
        else src_eof = true;
        break;
      }
    }
    return n;
  }

  // Appends more text to the buffer (compacting it first).
  void fill() {
    if (pos > 0) {
      std::memmove(buf.get(), buf.get() + pos, lim - pos);
      base += pos;
      lim -= pos;
      scan -= pos;
      pos = 0;
    }
    const std::size_t room = std::min(buf_size - 1 - lim, kReadChunk);
    char *dst = buf.get() + lim;
    const std::size_t n = gz ? read_gz(dst, room) : read_plain(dst, room);
    if (binary_at == kNoBinary && n > 0) {
      const auto *u = reinterpret_cast<const unsigned char *>(dst);
      if (const unsigned char *b = find_binary(u, u + n)) {
        binary_at = base + lim + static_cast<uint64_t>(b - u);
        binary_byte = *b;
      }
    }
    lim += n;
    stats.bytes += n;
  }

  [[noreturn]] void binary_error(long line) const {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02x", binary_byte);
    std::string m = std::string("binary data (byte ") + hex + " at offset " +
                    std::to_string(binary_at) + "): not a CARMEN text log";
    if (!gz && gzip_magic)
      m += " (the file is gzip-compressed but its name does not end in .gz)";
    fail(line, m);
  }

  // Next line into [b, e) (without '\n'). False at the end of the data.
  bool next_line(const char *&b, const char *&e) {
    for (;;) {
      char *const data = buf.get();
      const void *nl = scan < lim ? std::memchr(data + scan, '\n', lim - scan) : nullptr;
      if (nl) {
        const std::size_t at = static_cast<std::size_t>(static_cast<const char *>(nl) - data);
        if (binary_at != kNoBinary && binary_at < base + at) binary_error(line_no + 1);
        if (skipping) {  // the end of an over-long line: drop it
          skipping = false;
          pos = scan = at + 1;
          continue;
        }
        ++line_no;
        if (at - pos > opt.max_line_length) {
          pos = scan = at + 1;
          too_long();
          continue;
        }
        b = data + pos;
        e = data + at;
        pos = scan = at + 1;
        return true;
      }
      scan = lim;
      if (binary_at != kNoBinary && binary_at < base + lim) binary_error(line_no + 1);
      if (skipping) pos = scan = lim;  // discard what we have of the long line
      if (!skipping && lim - pos > opt.max_line_length) {
        // Skip it before reporting it: in strict mode too_long() throws, and a
        // later next() must go on after this line, not report it again.
        ++line_no;
        skipping = true;
        pos = scan = lim;
        too_long();
      }
      if (!src_error.empty()) fail(line_no + (skipping ? 0 : 1), src_error);
      if (src_eof) {
        if (pos < lim && !skipping) {  // a last line without '\n'
          ++line_no;
          b = data + pos;
          e = data + lim;
          pos = scan = lim;
          return true;
        }
        return false;
      }
      fill();
    }
  }

  void too_long() {
    const std::string m = "line longer than " + std::to_string(opt.max_line_length) +
                          " bytes (binary data or a damaged log?)";
    if (opt.strict) fail(line_no, m);
    count_bad(BadLine::TOO_LONG);
  }

  void count_bad(BadLine k) {
    const int i = static_cast<int>(k);
    ++stats.bad_lines[i];
    ++stats.lines;
    if (stats.first_bad_line[i] == 0) stats.first_bad_line[i] = line_no;
  }

  void note_unknown(const char *b, const char *e) {
    ++stats.unknown_lines;
    std::string_view name(b, static_cast<std::size_t>(e - b));
    if (name.size() > 64) name = name.substr(0, 64);
    for (auto &u : stats.unknown_names) {
      if (u.first == name) {
        ++u.second;
        return;
      }
    }
    if (stats.unknown_names.size() < 16) stats.unknown_names.emplace_back(std::string(name), 1);
  }

  void count_ranges(const std::vector<float> &r) {
    if (all_plain_ranges(r)) return;
    for (float v : r) {
      if (__builtin_expect(!(v >= 0.0f) || v > FLT_MAX, 0)) {
        if (std::isnan(v)) ++stats.nan_ranges;
        else if (std::isinf(v)) ++stats.inf_ranges;
        else ++stats.negative_ranges;
      }
    }
  }

  bool next(LogMessage &msg) {
    const char *b, *e;
    while (next_line(b, e)) {
      const char *name_end = nullptr;
      const LineKind k = parse_log_line(b, e, msg, &err, &name_end);
      switch (k) {
        case LineKind::MESSAGE:
          ++stats.lines;
          ++stats.messages[static_cast<int>(msg.type)];
          msg.line = line_no;
          if (is_laser_message(msg.type)) count_ranges(msg.laser.range);
          return true;
        case LineKind::BLANK:
          ++stats.lines;
          ++stats.blank_lines;
          break;
        case LineKind::COMMENT:
          ++stats.lines;
          ++stats.comment_lines;
          break;
        case LineKind::UNKNOWN: {
          ++stats.lines;
          const char *p = b;
          while (p < name_end && is_sep(*p)) ++p;
          note_unknown(p, name_end);
          break;
        }
        case LineKind::BAD:
          if (opt.strict) fail(line_no, err.message);
          count_bad(err.kind);
          break;
      }
    }
    return false;
  }
};

LogReader::LogReader(const std::string &path, LogReaderOptions options)
    : impl_(new Impl) {
  impl_->path = path;
  impl_->opt = options;
  impl_->open();
  impl_->fill();
  if (impl_->lim == 0) {
    if (!impl_->src_error.empty()) impl_->fail(0, impl_->src_error);
    impl_->fail(0, impl_->gz ? "empty log: the gzip stream holds no data" : "empty file");
  }
}

LogReader::~LogReader() = default;
LogReader::LogReader(LogReader &&) noexcept = default;
LogReader &LogReader::operator=(LogReader &&) noexcept = default;

bool LogReader::next(LogMessage &msg) { return impl_->next(msg); }
const LogStats &LogReader::stats() const { return impl_->stats; }
const std::string &LogReader::path() const { return impl_->path; }
const LogReaderOptions &LogReader::options() const { return impl_->opt; }
uint64_t LogReader::compressed_bytes_read() const {
  return impl_->inflater ? impl_->inflater->compressed_read() : impl_->comp_read;
}
uint64_t LogReader::file_size() const { return impl_->size; }
bool LogReader::compressed() const { return impl_->gz; }

std::vector<LogMessage> read_log(const std::string &path, LogReaderOptions options,
                                 LogStats *stats) {
  LogReader reader(path, options);
  std::vector<LogMessage> out;
  LogMessage m;
  while (reader.next(m)) out.push_back(m);
  if (stats) *stats = reader.stats();
  return out;
}

}  // namespace carmen
