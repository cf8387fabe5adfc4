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
// What a read may keep: the chunk's bytes, then for the C structure each
// zone's name, NUL and pointer and each link's structure, keys and points,
// every allocation counted with kAllocOverhead more (malloc's header and
// minimum). CARMEN's hierarchies name a handful of zones (the named gridmap
// chunks of the same file) and the doors between them; the budget is far
// above that and bounds what a few kilobytes of .gz claiming millions of
// zones could make us allocate. Nothing is allocated before a whole payload
// was walked and found inside it.
constexpr uint64_t kMaxHmapKeptBytes = uint64_t(64) << 20;
constexpr uint64_t kAllocOverhead = 16;

// Bounds-checked little-endian reads of a payload (a view into the chunk's
// bytes); errors name the file.
class Cursor {
 public:
  Cursor(const char *bytes, size_t size, const char *file) : b_(bytes), n_(size), file_(file) {}
  int32_t i32() {
    need(4);
    const auto *p = reinterpret_cast<const unsigned char *>(b_ + pos_);
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
  // The next NUL-terminated name: its first byte, its length in *len.
  const char *name(size_t *len) {
    const void *nul = left() == 0 ? nullptr : std::memchr(b_ + pos_, '\0', left());
    if (nul == nullptr) fail("a zone name has no terminating NUL");
    const char *s = b_ + pos_;
    *len = static_cast<size_t>(static_cast<const char *>(nul) - s);
    if (*len > kMaxZoneName) fail("a zone name is over 127 characters");
    pos_ += *len + 1;
    return s;
  }
  // A count of items of at least min_bytes each that the payload can hold.
  int32_t count(const char *what, size_t min_bytes) {
    const int32_t n = i32();
    if (n < 0 || uint64_t(n) * min_bytes > left())
      fail(std::string("invalid ") + what + " count " + std::to_string(n));
    return n;
  }
  size_t left() const { return n_ - pos_; }
  [[noreturn]] void fail(const std::string &what, carmen::ErrorCode code = carmen::ErrorCode::BadInput) const {
    throw carmen::FileError(file_, "HMAP chunk: " + what + " (payload byte " + std::to_string(pos_) + ")", code);
  }

 private:
  void need(size_t n) const {
    if (left() < n) fail("payload ends early");
  }
  const char *b_;
  size_t n_;
  const char *file_;
  size_t pos_ = 0;
};

void free_hmap(carmen_hmap_t &h) {
  for (int i = 0; h.zone_names != nullptr && i < h.num_zones; ++i) std::free(h.zone_names[i]);
  for (int i = 0; h.links != nullptr && i < h.num_links; ++i) {
    std::free(h.links[i].keys);
    std::free(h.links[i].points);
  }
  std::free(h.zone_names);
  std::free(h.links);
}

// calloc() of n items (at least one byte); throws std::bad_alloc.
template <typename T>
T *c_array(size_t n) {
  void *p = std::calloc(n == 0 ? 1 : n, sizeof(T));
  if (p == nullptr) throw std::bad_alloc();
  return static_cast<T *>(p);
}

// Walks a payload, counting what the C structure of it keeps (added to
// *kept, refused past kMaxHmapKeptBytes). With `out` (a walk already passed
// without), fills *out as it goes; out's counts are set as soon as its
// arrays exist, so that free_hmap frees whatever was made.
void walk_hmap(Cursor &in, uint64_t *kept, carmen_hmap_t *out) {
  const auto keep = [&](uint64_t bytes) {
    *kept += bytes;
    if (*kept > kMaxHmapKeptBytes)
      in.fail("its zones and links would take more than " + std::to_string(kMaxHmapKeptBytes >> 20) +
              " MiB (the HMAP reader's limit): refused rather than allocated",
              carmen::ErrorCode::TooLarge);
  };
  const int32_t num_zones = in.count("zone", 1);
  keep(uint64_t(num_zones) * sizeof(char *) + kAllocOverhead);
  if (out != nullptr) {
    out->zone_names = c_array<char *>(size_t(num_zones));
    out->num_zones = num_zones;
  }
  for (int32_t i = 0; i < num_zones; ++i) {
    size_t len = 0;
    const char *name = in.name(&len);
    keep(len + 1 + kAllocOverhead);
    if (out != nullptr) {
      out->zone_names[i] = c_array<char>(len + 1);
      std::memcpy(out->zone_names[i], name, len);
    }
  }
  const int32_t num_links = in.count("link", 8);
  keep(uint64_t(num_links) * sizeof(carmen_hmap_link_t) + kAllocOverhead);
  if (out != nullptr) {
    out->links = c_array<carmen_hmap_link_t>(size_t(num_links));
    out->num_links = num_links;
  }
  for (int32_t i = 0; i < num_links; ++i) {
    const int type = in.i32();
    const int n = points_per_key(type);
    if (n == 0) in.fail("unknown link type " + std::to_string(type));
    const int32_t degree = in.count("link degree", 4 + 12 * size_t(n));
    const size_t num_points = size_t(n) * size_t(degree);
    keep(uint64_t(degree) * sizeof(int) + num_points * sizeof(carmen_point_t) + 2 * kAllocOverhead);
    carmen_hmap_link_t *l = out != nullptr ? &out->links[i] : nullptr;
    if (l != nullptr) {
      l->type = type;
      l->degree = degree;
      l->num_points = static_cast<int>(num_points);
      l->keys = c_array<int>(size_t(degree));
      l->points = c_array<carmen_point_t>(num_points);
    }
    for (int32_t j = 0; j < degree; ++j) {
      const int32_t key = in.i32();
      if (key < 0 || key >= num_zones) in.fail("link key out of range");
      if (l != nullptr) l->keys[j] = key;
    }
    for (size_t k = 0; k < num_points; ++k) {
      const double x = in.f32(), y = in.f32(), theta = in.f32();
      if (l != nullptr) l->points[k] = carmen_point_t{x, y, theta};
    }
  }
  if (in.left() != 0) in.fail(std::to_string(in.left()) + " bytes left over after the last link");
}

// The payload checked whole (and its cost counted) first, then built; a
// failed allocation frees what was made.
carmen_hmap_t parse_hmap(const char *payload, size_t size, uint64_t kept, const char *file) {
  {
    Cursor check(payload, size, file);
    uint64_t counted = kept;
    walk_hmap(check, &counted, nullptr);
  }
  carmen_hmap_t h{};
  try {
    Cursor in(payload, size, file);
    walk_hmap(in, &kept, &h);
  } catch (...) {
    free_hmap(h);
    throw;
  }
  return h;
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
    // The chunk's bytes count too: a size past the budget is refused before
    // they are read (a .gz chunk's size is not checked against the file).
    if (uint64_t(c.size) > kMaxHmapKeptBytes)
      throw carmen::FileError(filename, "the HMAP chunk at byte " + std::to_string(c.offset) + " claims " +
                                            std::to_string(c.size) + " bytes, more than the " +
                                            std::to_string(kMaxHmapKeptBytes >> 20) +
                                            " MiB the HMAP reader takes: refused rather than read",
                              carmen::ErrorCode::TooLarge);
    const std::string body = carmen::read_chunk_body(filename, c);
    // A named chunk's name and NUL come between the description and the payload.
    const size_t skip = 10 + (c.named() ? c.name.size() + 1 : 0);
    if (skip > body.size()) throw carmen::FileError(filename, "HMAP chunk: its name runs past its end");
    *hmap = parse_hmap(body.data() + skip, body.size() - skip, body.size(), filename);
    return 0;
  });
}

}  // extern "C"
