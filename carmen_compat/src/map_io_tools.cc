// CARMEN's map_io utilities that work on whole files or on a map in memory:
// copy_comments, strip / vstrip, name_chunk, write_to_ppm and
// read_offlimits_chunk_into_map.
#include <algorithm>
#include <cerrno>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "carmen/map_io.h"
#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "carmen_stdio_results.h"
#include "map_io_support.h"

using carmen::map_io_detail::guarded;
using carmen::map_io_detail::put_bytes;

namespace {

constexpr size_t kCopyPiece = size_t{1} << 16;
constexpr uint64_t kOfflimitsWindow = uint64_t{16} << 20;  // decode_offlimits_payload's
constexpr size_t kMaxChunkName = 4096;

std::string map_id() { return std::string(CARMEN_MAP_LABEL) + CARMEN_MAP_VERSION; }

// Copies the '#' lines and the id; throws if the id is not there.
void copy_comments(carmen_FILE *in, carmen_FILE *out) {
  if (in == nullptr || out == nullptr) throw std::invalid_argument("no file given (NULL carmen_FILE)");
  std::string text;
  int c;
  while ((c = carmen_fgetc(in)) == '#') {
    text.push_back('#');
    while ((c = carmen_fgetc(in)) != EOF && c != '\n') text.push_back(static_cast<char>(c));
    if (c == EOF) throw std::runtime_error("input ends inside its comment lines");
    text.push_back('\n');
  }
  const std::string id = map_id();
  char rest[16];
  if (c == EOF || static_cast<char>(c) != id[0] || carmen_fread(rest, 1, 16, in) != 16 ||
      std::memcmp(rest, id.data() + 1, 16) != 0) {
    throw std::runtime_error("input is not a CARMEN map: no " + id + " after the comments");
  }
  put_bytes(out, text + id);
}

// Copies (out != NULL) or discards n bytes of in; throws if they are not there.
void pass_bytes(carmen_FILE *in, carmen_FILE *out, int64_t n) {
  std::vector<char> buf(kCopyPiece);
  while (n > 0) {
    const size_t k = static_cast<size_t>(std::min<int64_t>(n, int64_t(buf.size())));
    if (carmen_fread(buf.data(), 1, k, in) != k) throw std::runtime_error("input ends inside a chunk");
    if (out != nullptr) put_bytes(out, std::string(buf.data(), k));
    n -= int64_t(k);
  }
}

int32_t read_le_i32(const unsigned char *b) {
  const uint32_t u = uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  int32_t v;
  std::memcpy(&v, &u, 4);
  return v;
}

// Discards up to n bytes of in: a chunk stripped that the input ends
// inside goes as far as the input does, as CARMEN's fseek takes it.
void drop_bytes(carmen_FILE *in, int64_t n) {
  std::vector<char> buf(kCopyPiece);
  while (n > 0) {
    const size_t k = static_cast<size_t>(std::min<int64_t>(n, int64_t(buf.size())));
    if (carmen_fread(buf.data(), 1, k, in) != k) return;
    n -= int64_t(k);
  }
}

void seek_to(carmen_FILE *in, off_t at) {
  if (at < 0 || !carmen::checked_seek(in, at, SEEK_SET)) throw std::runtime_error("cannot seek in the input");
}

// One chunk whose type and size were read (`head`: those 5 bytes), copied
// (keep) or not. A chunk is copied by its size, but an OFFLIMITS chunk to
// where it really ends: CARMEN's writers size it wrongly (map_file.h,
// decode_offlimits_payload). One in CARMEN's layout is written as the chunk
// CARMEN meant (its lines, rectangles and size right), which CARMEN's own
// reader reads too; one in neither layout is copied by its size.
void copy_offlimits(carmen_FILE *in, carmen_FILE *out, const std::string &head, int32_t size, bool keep) {
  const off_t after_size = carmen_ftell(in);
  const bool named = CARMEN_MAP_CHUNK_IS_NAMED(static_cast<unsigned char>(head[0]));
  std::string desc(10, '\0'), name;
  if (carmen_fread(&desc[0], 1, 10, in) != 10) throw std::runtime_error("input ends inside a chunk");
  int c = 0;
  while (named && (c = carmen_fgetc(in)) != EOF && c != 0 && name.size() < kMaxChunkName)
    name.push_back(static_cast<char>(c));
  const int64_t declared = int64_t(size) - 10 - (named ? int64_t(name.size()) + 1 : 0);
  const off_t payload_at = carmen_ftell(in);
  std::vector<unsigned char> bytes;
  carmen::OffLimitsPayload d;
  if ((!named || c == 0) && uint64_t(std::max<int64_t>(declared, 0)) <= kOfflimitsWindow) {
    d = carmen::decode_offlimits_payload(bytes, uint64_t(std::max<int64_t>(declared, 0)), named,
                                         [&](std::vector<unsigned char> &b, uint64_t want) {
                                           const size_t old = b.size();
                                           if (want <= old) return;
                                           b.resize(static_cast<size_t>(want));
                                           const size_t got = carmen_fread(b.data() + old, 1, b.size() - old, in);
                                           b.resize(old + (got <= b.size() - old ? got : 0));  // -1: none
                                         });
  }
  if (!d.ok) {  // as any chunk
    seek_to(in, after_size);
    if (keep) put_bytes(out, head);
    pass_bytes(in, keep ? out : nullptr, size);
    return;
  }
  seek_to(in, payload_at + off_t(d.length));
  if (!keep) return;
  if (d.carmen_layout && !(named && name.empty())) {
    put_bytes(out, carmen::encode_offlimits_chunk(d.offlimits, name));
  } else {
    put_bytes(out, head + desc + (named ? name + std::string(1, '\0') : std::string()) +
                       std::string(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(d.length)));
  }
}

// The chunks after the id: each one copied unless its type is in strip. As
// in CARMEN, whose table is indexed by the raw type byte, a named chunk
// (type | 0x80) is never stripped: a map's named gridmaps, places or hmap
// zones survive maptool's strip, rotate and add_place.
void copy_chunks(carmen_FILE *in, carmen_FILE *out, const bool strip[128]) {
  int type;
  while ((type = carmen_fgetc(in)) != EOF) {
    unsigned char size_bytes[4];
    if (carmen_fread(size_bytes, 1, 4, in) != 4) throw std::runtime_error("input ends inside a chunk header");
    const int32_t size = read_le_i32(size_bytes);
    if (size < 10) throw std::runtime_error("damaged chunk: size " + std::to_string(size) + " (at least 10)");
    const bool keep = CARMEN_MAP_CHUNK_IS_NAMED(type) || !strip[type];
    const std::string head =
        std::string(1, static_cast<char>(type)) + std::string(reinterpret_cast<char *>(size_bytes), 4);
    if ((type & ~CARMEN_MAP_NAMED_CHUNK_FLAG) == CARMEN_MAP_OFFLIMITS_CHUNK) {
      copy_offlimits(in, out, head, size, keep);
    } else if (!keep && type == CARMEN_MAP_GRIDMAP_CHUNK) {
      drop_bytes(in, size);  // a gridmap cut short is read (map_file.h), so it is stripped too
    } else {
      if (keep) put_bytes(out, head);
      pass_bytes(in, keep ? out : nullptr, size);
    }
  }
}

// ---- Off-limits ------------------------------------------------------------
// CARMEN's Bresenham walk (global.c), both ends included; DESIGN §2.1.
template <typename F>
void bresenham(int x1, int y1, int x2, int y2, F &&visit) {
  const bool steep = std::abs(double(y2 - y1) / double(x2 - x1)) > 1;  // 0/0 is NaN: not steep
  int a1 = steep ? y1 : x1, b1 = steep ? x1 : y1, a2 = steep ? y2 : x2, b2 = steep ? x2 : y2;
  const bool flipped = (long long)(x2 - x1) * (long long)(y2 - y1) < 0;
  if (flipped) {
    b1 = -b1;
    b2 = -b2;
  }
  const int inc = a2 > a1 ? 1 : -1;
  const long long dx = a2 - a1, dy = b2 - b1;
  const long long incr_e = 2 * dy * inc, incr_ne = 2 * (dy - dx) * inc;
  long long d = (2 * dy - dx) * inc;
  int a = a1, b = b1;
  while (true) {
    const int minor = flipped ? -b : b;
    if (steep)
      visit(minor, a);
    else
      visit(a, minor);
    if (a == a2) break;
    a += inc;
    if (d < 0 || (inc < 0 && d <= 0)) {
      d += incr_e;
    } else {
      d += incr_ne;
      b += inc;
    }
  }
}

void mark(carmen_map_p map, int x, int y) {
  if (x >= 0 && y >= 0 && x < map->config.x_size && y < map->config.y_size) map->map[x][y] += 2.0;
}

void apply_offlimits(const carmen_offlimits_t *list, int n, carmen_map_p map) {
  for (int i = 0; i < n; ++i) {
    const carmen_offlimits_t &o = list[i];
    if (o.type == CARMEN_OFFLIMITS_POINT_ID) {
      mark(map, o.x1, o.y1);
    } else if (o.type == CARMEN_OFFLIMITS_LINE_ID) {
      bresenham(o.x1, o.y1, o.x2, o.y2, [&](int x, int y) { mark(map, x, y); });
    } else if (o.type == CARMEN_OFFLIMITS_RECT_ID) {
      for (int x = o.x1; x <= o.x2; ++x) {
        for (int y = o.y1; y <= o.y2; ++y) mark(map, x, y);
      }
    }
  }
}

// ---- PPM ---------------------------------------------------------------------
// 0..255 from CARMEN's expression; its conversion to char truncates, and is
// undefined outside the range, where we clamp (NaN gives 0).
unsigned char to_byte(double t) {
  if (!(t >= 0)) return 0;
  if (t >= 255) return 255;
  return static_cast<unsigned char>(static_cast<int>(t));
}

void ppm_pixel(float v, std::string &out) {
  if (v == -1) {
    out += {'\0', '\0', '\xff'};
  } else if (v >= 2.0) {
    const auto c = static_cast<char>(to_byte(255 - 255 * (double(v) - 2.0)));
    out += {'\xff', c, c};
  } else {
    const auto c = static_cast<char>(to_byte(255.0f - 255.0f * v));  // float arithmetic, as CARMEN's
    out += {c, c, c};
  }
}

std::string ppm_bytes(const carmen_map_t &map) {
  const int sx = map.config.x_size, sy = map.config.y_size;
  std::string out = "P6\n" + std::to_string(sx) + " " + std::to_string(sy) + "\n255\n";
  out.reserve(out.size() + size_t(sx) * size_t(sy) * 3);
  for (int y = sy - 1; y >= 0; --y) {
    for (int x = 0; x < sx; ++x) ppm_pixel(map.map[x][y], out);
  }
  return out;
}

void check_map(const carmen_map_t *map) {
  if (map == nullptr || map->map == nullptr) throw std::invalid_argument("no map given (NULL)");
  if (map->config.x_size <= 0 || map->config.y_size <= 0) {
    throw std::invalid_argument("invalid map size " + std::to_string(map->config.x_size) + " x " +
                                std::to_string(map->config.y_size));
  }
  for (int x = 0; x < map->config.x_size; ++x) {
    if (map->map[x] == nullptr)
      throw std::invalid_argument("row " + std::to_string(x) + " of the map is NULL");
  }
}

void write_file(const char *filename, const std::string &bytes) {
  std::FILE *f = std::fopen(filename, "wb");
  if (f == nullptr) throw carmen::FileError(filename, std::string("cannot create: ") + std::strerror(errno));
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  if (std::fclose(f) != 0 || !ok) throw carmen::FileError(filename, "write failed (disk full?)");
}

// ---- Naming a chunk ----------------------------------------------------------
// The first chunk of `type`, named or not, found as CARMEN's advance finds it.
carmen::ChunkInfo first_chunk(const char *file, int type) {
  const auto c = carmen::find_first_chunk(file, type);
  if (!c) throw carmen::FileError(file, "has no " + carmen::chunk_type_name(type) + " chunk");
  return *c;
}

void check_name_free(const char *out_file, int type, const char *name) {
  const std::string wanted = name;
  if (carmen::find_first_chunk(out_file, type, &wanted)) {
    throw carmen::FileError(out_file, "already has a " + carmen::chunk_type_name(type) + " chunk named \"" +
                                          carmen::printable(name) + "\"");
  }
}

// The chunk as a named one: the description is kept as it was.
std::string named_copy(int type, const std::string &body, const char *name) {
  std::string bytes = carmen::encode_raw_chunk(type, body.substr(10), name);
  bytes.replace(5, 10, body, 0, 10);
  return bytes;
}

void append(const char *out_file, const std::string &bytes) {
  carmen_FILE *out = carmen_fopen(out_file, "a");
  if (out == nullptr)
    throw carmen::FileError(out_file, std::string("cannot append: ") + std::strerror(errno));
  const bool ok = carmen_fwrite(bytes.data(), 1, bytes.size(), out) == bytes.size();
  if (carmen_fclose(out) != 0 || !ok) throw carmen::FileError(out_file, "write failed (disk full?)");
}

}  // namespace

extern "C" {

int carmen_map_copy_comments(carmen_FILE *fp_in, carmen_FILE *fp_out) {
  return guarded(__func__, nullptr, [&] {
    copy_comments(fp_in, fp_out);
    return 0;
  });
}

int carmen_map_vstrip(carmen_FILE *fp_in, carmen_FILE *fp_out, int num_chunks, ...) {
  bool strip[128] = {};
  va_list ap;
  va_start(ap, num_chunks);
  bool bad = num_chunks < 0;
  int bad_value = num_chunks;
  for (int i = 0; i < num_chunks && !bad; ++i) {
    const int type = va_arg(ap, int);
    bad = type < 0 || type >= 128;
    bad_value = type;
    if (!bad) strip[type] = true;
  }
  va_end(ap);
  return guarded(__func__, nullptr, [&] {
    if (bad) throw std::invalid_argument("invalid chunk type or count " + std::to_string(bad_value));
    copy_comments(fp_in, fp_out);
    copy_chunks(fp_in, fp_out, strip);
    return 0;
  });
}

int carmen_map_strip(carmen_FILE *fp_in, carmen_FILE *fp_out, int chunk) {
  return carmen_map_vstrip(fp_in, fp_out, 1, chunk);
}

int carmen_map_name_chunk(const char *in_file, const char *out_file, int chunk_type, const char *chunk_name) {
  return guarded(__func__, in_file, [&] {
    if (in_file == nullptr || out_file == nullptr) throw std::invalid_argument("no file name given");
    if (chunk_name == nullptr || *chunk_name == '\0') throw std::invalid_argument("no chunk name given");
    const int type = chunk_type & ~CARMEN_MAP_NAMED_CHUNK_FLAG;
    const carmen::ChunkInfo c = first_chunk(in_file, type);
    if (c.named()) {
      throw carmen::FileError(in_file,
                              "its first " + carmen::chunk_type_name(type) + " chunk is already named");
    }
    const std::string body = carmen::read_chunk_body(in_file, c);
    check_name_free(out_file, type, chunk_name);
    append(out_file, named_copy(type, body, chunk_name));
    return 0;
  });
}

int carmen_map_write_to_ppm(carmen_map_p map, const char *output_filename) {
  return guarded(__func__, output_filename, [&] {
    if (output_filename == nullptr) throw std::invalid_argument("no file name given");
    check_map(map);
    write_file(output_filename, ppm_bytes(*map));
    return 0;
  });
}

int carmen_map_read_offlimits_chunk_into_map(const char *filename, carmen_map_p map) {
  if (map == nullptr || map->complete_map == nullptr) {
    std::fprintf(stderr, "%s: %s: no map to mark (NULL)\n", __func__, filename ? filename : "(null)");
    return -1;
  }
  carmen_offlimits_p list = nullptr;
  int n = 0;
  if (carmen_map_read_offlimits_chunk(filename, &list, &n) < 0) return -1;
  const int rc = guarded(__func__, filename, [&] {
    if (n == 0) throw carmen::FileError(filename, "the OFFLIMITS chunk is empty");  // -1, as in CARMEN
    check_map(map);
    apply_offlimits(list, n, map);
    return 0;
  });
  std::free(list);
  return rc;
}

}  // extern "C"
