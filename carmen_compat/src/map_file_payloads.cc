// The chunk payloads of fixed layout (map_file_payloads.h).
#include "map_file_payloads.h"

#include <cstdint>
#include <cstring>
#include <string>

#include "map_file_bytes.h"

namespace carmen::map_read {
namespace {

using namespace map_bytes;

// Bounds-checked parsing of a chunk payload held in memory.
class Cursor {
 public:
  Cursor(const unsigned char *p, size_t n) : p_(p), n_(n) {}
  size_t left() const { return n_ - i_; }
  const unsigned char *take(size_t k, const char *what) {
    if (k > left()) {
      throw ParseError{std::string("ends inside ") + what + " (needs " + std::to_string(k) + " more bytes, " +
                       std::to_string(left()) + " left)"};
    }
    const unsigned char *r = p_ + i_;
    i_ += k;
    return r;
  }
  int32_t i32(const char *what) { return get_i32(take(4, what)); }
  float f32(const char *what) { return get_f32(take(4, what)); }
  double f64(const char *what) { return get_f64(take(8, what)); }
  // A count whose items take at least `item_bytes` each: checked against what is left.
  size_t count(size_t item_bytes, const char *what) {
    const int32_t n = i32(what);
    if (n < 0) throw ParseError{std::string("has a negative ") + what + " (" + std::to_string(n) + ")"};
    if (item_bytes > 0 && static_cast<uint64_t>(n) * item_bytes > left()) {
      throw ParseError{std::string("claims ") + std::to_string(n) + " " + what + " but holds only " +
                       std::to_string(left()) + " more bytes"};
    }
    return static_cast<size_t>(n);
  }
  void expect_end() const {
    if (left() != 0) {
      throw ParseError{"has " + std::to_string(left()) + " unexpected bytes at its end"};
    }
  }

 private:
  const unsigned char *p_;
  size_t n_;
  size_t i_ = 0;
};

// Text of a fixed-width field: up to the first NUL, trailing spaces removed.
std::string field_text(const unsigned char *p, size_t width) {
  size_t n = 0;
  while (n < width && p[n] != 0) ++n;
  while (n > 0 && p[n - 1] == ' ') --n;
  return std::string(reinterpret_cast<const char *>(p), n);
}

}  // namespace

CreatorInfo parse_creator(const std::vector<unsigned char> &b) {
  // user[10], time_t, origin[80], description[80]
  if (b.size() != 174 && b.size() != 178) {
    throw ParseError{"has " + std::to_string(b.size()) +
                     " payload bytes; a creator needs 174 (32-bit time_t) or 178 (64-bit time_t)"};
  }
  CreatorInfo c;
  c.time_bytes = static_cast<int>(b.size()) - 170;
  Cursor cur(b.data(), b.size());
  c.user = field_text(cur.take(10, "the user name"), 10);
  if (c.time_bytes == 4) {
    c.time = get_i32(cur.take(4, "the time"));
  } else {
    const uint64_t u = get_u64(cur.take(8, "the time"));
    std::memcpy(&c.time, &u, 8);
  }
  c.origin = field_text(cur.take(80, "the origin"), 80);
  c.description = field_text(cur.take(80, "the description"), 80);
  return c;
}

GlobalOffset parse_offset(const std::vector<unsigned char> &b) {
  if (b.size() != 24) {
    throw ParseError{"has " + std::to_string(b.size()) + " payload bytes; an offset needs 24 (3 doubles)"};
  }
  Cursor cur(b.data(), b.size());
  GlobalOffset o;
  o.x = cur.f64("x");
  o.y = cur.f64("y");
  o.theta = cur.f64("theta");
  return o;
}

PlaceList parse_places(const std::vector<unsigned char> &b) {
  Cursor cur(b.data(), b.size());
  const size_t n = cur.count(4 + 20 + 8, "places");
  PlaceList places;
  places.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    Place p;
    p.type = cur.i32("a place type");
    p.name = field_text(cur.take(20, "a place name"), 20);
    p.x = cur.f32("a place");
    p.y = cur.f32("a place");
    if (p.type == kNamedPose || p.type == kLocalizationInit) p.theta = cur.f32("a place");
    if (p.type == kLocalizationInit) {
      p.x_std = cur.f32("a place");
      p.y_std = cur.f32("a place");
      p.theta_std = cur.f32("a place");
    }
    if (p.type != kNamedPosition && p.type != kNamedPose && p.type != kLocalizationInit) {
      throw ParseError{"has place " + std::to_string(i) + " with unknown type " + std::to_string(p.type) +
                       " (expected 0 position, 1 pose or 2 localization init, as CARMEN's map.h)"};
    }
    places.push_back(std::move(p));
  }
  cur.expect_end();
  return places;
}

LaserScanList parse_laserscans(const std::vector<unsigned char> &b) {
  Cursor cur(b.data(), b.size());
  const size_t n = cur.count(16, "scans");
  LaserScanList scans;
  scans.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    LaserScan s;
    s.x = cur.f32("a scan pose");
    s.y = cur.f32("a scan pose");
    s.theta = cur.f32("a scan pose");
    const size_t nr = cur.count(4, "readings");
    s.ranges.resize(nr);
    const unsigned char *p = cur.take(4 * nr, "the readings");
    for (size_t k = 0; k < nr; ++k) s.ranges[k] = get_f32(p + 4 * k);
    scans.push_back(std::move(s));
  }
  cur.expect_end();
  return scans;
}

}  // namespace carmen::map_read
