// CARMEN's hierarchical-map chunk (HMAP, code 3): carmen_map_write_hmap_chunk
// and carmen_map_read_hmap_chunk. Payload, all little-endian:
//   int32 num_zones, num_zones NUL-terminated names,
//   int32 num_links, per link: int32 type, int32 degree, degree int32 keys,
//   then for each key its points (2 for a door, 1 for an elevator) as
//   float32 x, y, theta.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "carmen/map_io.h"
#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_io_support.h"

using carmen::map_io_detail::guarded;
using carmen::map_io_detail::put_bytes;

namespace {

constexpr size_t kMaxZoneName = 127;  // CARMEN reads a name into char[128]

// Points per key of a link type; 0 for a type CARMEN does not know.
int points_per_key(int type) {
  return type == CARMEN_HMAP_LINK_DOOR ? 2 : type == CARMEN_HMAP_LINK_ELEVATOR ? 1 : 0;
}

void put_u32(std::string &s, uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void put_i32(std::string &s, int32_t v) { put_u32(s, static_cast<uint32_t>(v)); }
void put_f32(std::string &s, float v) {
  uint32_t u;
  std::memcpy(&u, &v, 4);
  put_u32(s, u);
}

// ---- Writing -----------------------------------------------------------------
void put_zone_names(std::string &s, const carmen_hmap_t &h) {
  if (h.num_zones < 0 || (h.num_zones > 0 && h.zone_names == nullptr))
    throw std::invalid_argument("invalid zone list");
  put_i32(s, h.num_zones);
  for (int i = 0; i < h.num_zones; ++i) {
    const char *name = h.zone_names[i];
    if (name == nullptr) throw std::invalid_argument("zone " + std::to_string(i) + " has no name (NULL)");
    if (std::strlen(name) > kMaxZoneName) {
      throw std::invalid_argument("zone " + std::to_string(i) + "'s name is over 127 characters");
    }
    s.append(name, std::strlen(name) + 1);
  }
}

void put_link(std::string &s, const carmen_hmap_link_t &l, int num_zones, int index) {
  const std::string which = "link " + std::to_string(index);
  const int n = points_per_key(l.type);
  if (n == 0) throw std::invalid_argument(which + " has unknown type " + std::to_string(l.type));
  if (l.degree < 0 || (l.degree > 0 && (l.keys == nullptr || l.points == nullptr))) {
    throw std::invalid_argument(which + " has an invalid degree or NULL keys / points");
  }
  put_i32(s, l.type);
  put_i32(s, l.degree);
  for (int j = 0; j < l.degree; ++j) {
    if (l.keys[j] < 0 || l.keys[j] >= num_zones)
      throw std::invalid_argument(which + " has a key out of range");
    put_i32(s, l.keys[j]);
  }
  for (int k = 0; k < n * l.degree; ++k) {
    put_f32(s, static_cast<float>(l.points[k].x));
    put_f32(s, static_cast<float>(l.points[k].y));
    put_f32(s, static_cast<float>(l.points[k].theta));
  }
}

std::string hmap_payload(const carmen_hmap_t *h) {
  if (h == nullptr) throw std::invalid_argument("no hmap given (NULL)");
  std::string s;
  put_zone_names(s, *h);
  if (h->num_links < 0 || (h->num_links > 0 && h->links == nullptr))
    throw std::invalid_argument("invalid link list");
  put_i32(s, h->num_links);
  for (int i = 0; i < h->num_links; ++i) put_link(s, h->links[i], h->num_zones, i);
  return s;
}

// ---- Reading -----------------------------------------------------------------
// Bounds-checked little-endian reads of a payload; errors name the file.
class Cursor {
 public:
  Cursor(const std::string &bytes, const char *file) : b_(bytes), file_(file) {}
  int32_t i32() {
    need(4);
    const auto *p = reinterpret_cast<const unsigned char *>(b_.data() + pos_);
    pos_ += 4;
    const uint32_t u = uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
    int32_t v;
    std::memcpy(&v, &u, 4);
    return v;
  }
  float f32() {
    const int32_t i = i32();
    float v;
    std::memcpy(&v, &i, 4);
    return v;
  }
  std::string name() {
    const size_t end = b_.find('\0', pos_);
    if (end == std::string::npos) fail("a zone name has no terminating NUL");
    if (end - pos_ > kMaxZoneName) fail("a zone name is over 127 characters");
    std::string s = b_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return s;
  }
  // A count of items of at least min_bytes each that the payload can hold.
  int32_t count(const char *what, size_t min_bytes) {
    const int32_t n = i32();
    if (n < 0 || uint64_t(n) * min_bytes > left())
      fail(std::string("invalid ") + what + " count " + std::to_string(n));
    return n;
  }
  size_t left() const { return b_.size() - pos_; }
  [[noreturn]] void fail(const std::string &what) const {
    throw carmen::FileError(file_, "HMAP chunk: " + what + " (payload byte " + std::to_string(pos_) + ")");
  }

 private:
  void need(size_t n) const {
    if (left() < n) fail("payload ends early");
  }
  const std::string &b_;
  const char *file_;
  size_t pos_ = 0;
};

struct Link {
  int type = 0, degree = 0;
  std::vector<int> keys;
  std::vector<carmen_point_t> points;
};

Link parse_link(Cursor &in, int num_zones) {
  Link l;
  l.type = in.i32();
  const int n = points_per_key(l.type);
  if (n == 0) in.fail("unknown link type " + std::to_string(l.type));
  l.degree = in.count("link degree", 4 + 12 * size_t(n));
  for (int j = 0; j < l.degree; ++j) {
    l.keys.push_back(in.i32());
    if (l.keys.back() < 0 || l.keys.back() >= num_zones) in.fail("link key out of range");
  }
  for (int k = 0; k < n * l.degree; ++k) {
    const double x = in.f32(), y = in.f32(), theta = in.f32();
    l.points.push_back({x, y, theta});
  }
  return l;
}

void free_hmap(carmen_hmap_t &h) {
  for (int i = 0; h.zone_names != nullptr && i < h.num_zones; ++i) std::free(h.zone_names[i]);
  for (int i = 0; h.links != nullptr && i < h.num_links; ++i) {
    std::free(h.links[i].keys);
    std::free(h.links[i].points);
  }
  std::free(h.zone_names);
  std::free(h.links);
}

// malloc() of n items (at least one byte); throws std::bad_alloc.
template <typename T>
T *c_array(size_t n) {
  void *p = std::calloc(n == 0 ? 1 : n, sizeof(T));
  if (p == nullptr) throw std::bad_alloc();
  return static_cast<T *>(p);
}

void fill_link(carmen_hmap_link_t &out, const Link &l) {
  out.type = l.type;
  out.degree = l.degree;
  out.num_points = static_cast<int>(l.points.size());
  out.keys = c_array<int>(l.keys.size());
  out.points = c_array<carmen_point_t>(l.points.size());
  if (!l.keys.empty()) std::memcpy(out.keys, l.keys.data(), l.keys.size() * sizeof(int));
  if (!l.points.empty()) std::memcpy(out.points, l.points.data(), l.points.size() * sizeof(carmen_point_t));
}

// Builds the C structure; frees what it made if an allocation fails.
carmen_hmap_t to_c(const std::vector<std::string> &zones, const std::vector<Link> &links) {
  carmen_hmap_t h{};
  try {
    h.zone_names = c_array<char *>(zones.size());
    h.num_zones = static_cast<int>(zones.size());
    for (size_t i = 0; i < zones.size(); ++i) {
      h.zone_names[i] = c_array<char>(zones[i].size() + 1);
      std::memcpy(h.zone_names[i], zones[i].c_str(), zones[i].size() + 1);
    }
    h.links = c_array<carmen_hmap_link_t>(links.size());
    h.num_links = static_cast<int>(links.size());
    for (size_t i = 0; i < links.size(); ++i) fill_link(h.links[i], links[i]);
  } catch (...) {
    free_hmap(h);
    throw;
  }
  return h;
}

carmen_hmap_t parse_hmap(const std::string &payload, const char *file) {
  Cursor in(payload, file);
  std::vector<std::string> zones(static_cast<size_t>(in.count("zone", 1)));
  for (std::string &z : zones) z = in.name();
  std::vector<Link> links(static_cast<size_t>(in.count("link", 8)));
  for (Link &l : links) l = parse_link(in, static_cast<int>(zones.size()));
  if (in.left() != 0) in.fail(std::to_string(in.left()) + " bytes left over after the last link");
  return to_c(zones, links);
}

// The first HMAP chunk, named or not, as CARMEN's advance finds it.
carmen::ChunkInfo first_hmap(const char *file) {
  const auto c = carmen::find_first_chunk(file, CARMEN_MAP_HMAP_CHUNK);
  if (!c) throw carmen::FileError(file, "has no HMAP chunk");
  return *c;
}

}  // namespace

extern "C" {

int carmen_map_write_hmap_chunk(carmen_FILE *fp, carmen_hmap_p hmap) {
  return guarded(__func__, nullptr, [&] {
    put_bytes(fp, carmen::encode_raw_chunk(CARMEN_MAP_HMAP_CHUNK, hmap_payload(hmap)));
    return 0;
  });
}

int carmen_map_read_hmap_chunk(const char *filename, carmen_hmap_p hmap) {
  if (hmap != nullptr) *hmap = carmen_hmap_t{};  // cleared first: a failure leaves no stale pointers
  return guarded(__func__, filename, [&] {
    carmen::map_io_detail::need_name(filename);
    if (hmap == nullptr) throw std::invalid_argument("no hmap given (NULL)");
    const carmen::ChunkInfo c = first_hmap(filename);
    const std::string body = carmen::read_chunk_body(filename, c);
    // A named chunk's name and NUL come between the description and the payload.
    const size_t skip = 10 + (c.named() ? c.name.size() + 1 : 0);
    *hmap = parse_hmap(body.substr(skip), filename);
    return 0;
  });
}

}  // extern "C"
