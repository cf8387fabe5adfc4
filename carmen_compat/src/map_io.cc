// CARMEN's map_io C API on top of carmen_compat/map_file.h.
#include "carmen/map_io.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <new>
#include <string>

#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_io_support.h"

static_assert(CARMEN_MAP_GRIDMAP_CHUNK == carmen::kGridmapChunk, "chunk code");
static_assert(CARMEN_MAP_OFFLIMITS_CHUNK == carmen::kOfflimitsChunk, "chunk code");
static_assert(CARMEN_MAP_HMAP_CHUNK == carmen::kHmapChunk, "chunk code");
static_assert(CARMEN_MAP_PLACES_CHUNK == carmen::kPlacesChunk, "chunk code");
static_assert(CARMEN_MAP_EXPECTED_CHUNK == carmen::kExpectedChunk, "chunk code");
static_assert(CARMEN_MAP_LASERSCANS_CHUNK == carmen::kLaserscansChunk, "chunk code");
static_assert(CARMEN_MAP_CREATOR_CHUNK == carmen::kCreatorChunk, "chunk code");
static_assert(CARMEN_MAP_GLOBAL_OFFSET_CHUNK == carmen::kGlobalOffsetChunk, "chunk code");
static_assert(CARMEN_MAP_NAMED_CHUNK_FLAG == carmen::kNamedChunkFlag, "chunk code");
static_assert(CARMEN_NAMED_POSITION_TYPE == carmen::kNamedPosition, "place type");
static_assert(CARMEN_NAMED_POSE_TYPE == carmen::kNamedPose, "place type");
static_assert(CARMEN_LOCALIZATION_INIT_TYPE == carmen::kLocalizationInit, "place type");

namespace {

using carmen::map_io_detail::guarded;
using carmen::map_io_detail::report;

carmen::MapFile read_file(const char *filename) {
  if (filename == nullptr) throw std::invalid_argument("no file name given");
  return carmen::read_map_file(filename);
}

[[noreturn]] void missing(const char *filename, const char *what) {
  throw carmen::FileError(filename, std::string("has no ") + what + " chunk");
}

[[noreturn]] void missing_named(const char *filename, const char *what, const char *name) {
  throw carmen::FileError(filename, std::string("has no ") + what + " chunk named \"" +
                                        carmen::printable(name ? name : "") + "\"");
}

template <typename T>
const T *find_named(const carmen::MapFile &m, const char *name) {
  if (name == nullptr) return nullptr;
  for (const carmen::NamedChunk &nc : m.named) {
    if (nc.name == name) {
      if (const T *p = std::get_if<T>(&nc.payload)) return p;
    }
  }
  return nullptr;
}

int write_bytes(carmen_FILE *fp, const std::string &bytes, const char *func) {
  if (fp == nullptr) {
    report(func, "no file given (NULL carmen_FILE)");
    return -1;
  }
  if (carmen_fwrite(bytes.data(), 1, bytes.size(), fp) != bytes.size()) {
    report(func, "write failed");
    return -1;
  }
  return 0;
}

carmen::GridMap grid_from(float **prob, int size_x, int size_y, double resolution) {
  if (prob == nullptr) throw std::invalid_argument("no grid given (NULL prob)");
  if (size_x <= 0 || size_y <= 0) {
    throw std::invalid_argument("invalid map size " + std::to_string(size_x) + " x " +
                                std::to_string(size_y));
  }
  carmen::GridMap g = carmen::GridMap::filled(size_x, size_y, resolution, 0.0f);
  for (int x = 0; x < size_x; ++x) {
    if (prob[x] == nullptr) throw std::invalid_argument("row " + std::to_string(x) + " of the grid is NULL");
    std::memcpy(&g.cells[size_t(x) * size_t(size_y)], prob[x], sizeof(float) * size_t(size_y));
  }
  return g;
}

carmen::PlaceList places_from(const carmen_place_t *places, int n) {
  if (n < 0 || (n > 0 && places == nullptr)) throw std::invalid_argument("invalid place list");
  carmen::PlaceList out(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const carmen_place_t &p = places[i];
    carmen::Place &q = out[size_t(i)];
    q.type = p.type;
    q.name.assign(p.name, strnlen(p.name, sizeof p.name));
    q.x = p.x;
    q.y = p.y;
    q.theta = p.theta;
    q.x_std = p.x_std;
    q.y_std = p.y_std;
    q.theta_std = p.theta_std;
  }
  return out;
}

carmen::OffLimits offlimits_from(const carmen_offlimits_t *items, int n) {
  if (n < 0 || (n > 0 && items == nullptr)) throw std::invalid_argument("invalid off-limits list");
  carmen::OffLimits o;
  for (int i = 0; i < n; ++i) {
    const carmen_offlimits_t &it = items[i];
    switch (it.type) {
      case CARMEN_OFFLIMITS_POINT_ID: o.points.push_back({it.x1, it.y1}); break;
      case CARMEN_OFFLIMITS_LINE_ID: o.lines.push_back({it.x1, it.y1, it.x2, it.y2}); break;
      case CARMEN_OFFLIMITS_RECT_ID: o.rects.push_back({it.x1, it.y1, it.x2, it.y2}); break;
      default:
        throw std::invalid_argument("off-limits item " + std::to_string(i) + " has unknown type " +
                                    std::to_string(it.type));
    }
  }
  return o;
}

carmen::LaserScanList scans_from(const carmen_laser_scan_t *scans, int n) {
  if (n < 0 || (n > 0 && scans == nullptr)) throw std::invalid_argument("invalid scan list");
  carmen::LaserScanList out(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const carmen_laser_scan_t &s = scans[i];
    if (s.num_readings < 0 || (s.num_readings > 0 && s.range == nullptr)) {
      throw std::invalid_argument("scan " + std::to_string(i) + " has an invalid range array");
    }
    carmen::LaserScan &t = out[size_t(i)];
    t.x = s.x;
    t.y = s.y;
    t.theta = s.theta;
    t.ranges.assign(s.range, s.range + s.num_readings);
  }
  return out;
}

// A malloc()ed copy of `text`, as CARMEN's readers make for map_name.
char *malloc_copy(const char *text) {
  const size_t n = std::strlen(text) + 1;
  auto *copy = static_cast<char *>(std::malloc(n));
  if (copy == nullptr) throw std::bad_alloc();
  std::memcpy(copy, text, n);
  return copy;
}

void fill_config(const carmen::GridMap &g, const char *map_name, carmen_map_config_p config) {
  char *name = malloc_copy(map_name);
  config->x_size = g.size_x;
  config->y_size = g.size_y;
  config->resolution = g.resolution;
  config->map_name = name;
}

// map_name: what CARMEN's reader puts there (the file or the chunk name).
void fill_map(const carmen::GridMap &g, const char *map_name, carmen_map_p map) {
  const size_t n = g.cells.size();
  auto *cells = static_cast<float *>(std::malloc(sizeof(float) * n));
  auto **rows = static_cast<float **>(std::malloc(sizeof(float *) * size_t(g.size_x)));
  char *name = static_cast<char *>(std::malloc(std::strlen(map_name) + 1));
  if (cells == nullptr || rows == nullptr || name == nullptr) {
    std::free(cells);
    std::free(rows);
    std::free(name);
    throw std::bad_alloc();
  }
  std::strcpy(name, map_name);
  std::memcpy(cells, g.cells.data(), sizeof(float) * n);
  for (int x = 0; x < g.size_x; ++x) rows[x] = cells + size_t(x) * size_t(g.size_y);
  map->config.x_size = g.size_x;
  map->config.y_size = g.size_y;
  map->config.resolution = g.resolution;
  map->config.map_name = name;
  map->complete_map = cells;
  map->map = rows;
}

void fill_places(const carmen::PlaceList &in, carmen_map_placelist_p out) {
  carmen_place_t *arr = nullptr;
  if (!in.empty()) {
    arr = static_cast<carmen_place_t *>(std::calloc(in.size(), sizeof(carmen_place_t)));
    if (arr == nullptr) throw std::bad_alloc();
  }
  for (size_t i = 0; i < in.size(); ++i) {
    const carmen::Place &p = in[i];
    carmen_place_t &q = arr[i];
    q.type = p.type;
    q.size = 0;
    std::strncpy(q.name, p.name.c_str(), sizeof q.name - 1);
    q.x = p.x;
    q.y = p.y;
    q.theta = p.theta;
    q.x_std = p.x_std;
    q.y_std = p.y_std;
    q.theta_std = p.theta_std;
  }
  out->places = arr;
  out->num_places = static_cast<int>(in.size());
}

void fill_offlimits(const carmen::OffLimits &o, carmen_offlimits_p *list, int *length) {
  const size_t n = o.points.size() + o.lines.size() + o.rects.size();
  carmen_offlimits_t *arr = nullptr;
  if (n > 0) {
    arr = static_cast<carmen_offlimits_t *>(std::calloc(n, sizeof(carmen_offlimits_t)));
    if (arr == nullptr) throw std::bad_alloc();
  }
  size_t k = 0;
  for (const auto &p : o.points) arr[k++] = {CARMEN_OFFLIMITS_POINT_ID, p.x, p.y, 0, 0};
  for (const auto &l : o.lines) arr[k++] = {CARMEN_OFFLIMITS_LINE_ID, l.x1, l.y1, l.x2, l.y2};
  for (const auto &r : o.rects) arr[k++] = {CARMEN_OFFLIMITS_RECT_ID, r.x1, r.y1, r.x2, r.y2};
  *list = arr;
  *length = static_cast<int>(n);
}

void fill_scans(const carmen::LaserScanList &in, carmen_laser_scan_p *list, int *num) {
  carmen_laser_scan_t *arr = nullptr;
  if (!in.empty()) {
    arr = static_cast<carmen_laser_scan_t *>(std::calloc(in.size(), sizeof(carmen_laser_scan_t)));
    if (arr == nullptr) throw std::bad_alloc();
  }
  for (size_t i = 0; i < in.size(); ++i) {
    const carmen::LaserScan &s = in[i];
    carmen_laser_scan_t &t = arr[i];
    t.x = s.x;
    t.y = s.y;
    t.theta = s.theta;
    t.num_readings = static_cast<int>(s.ranges.size());
    if (!s.ranges.empty()) {
      t.range = static_cast<float *>(std::malloc(sizeof(float) * s.ranges.size()));
      if (t.range == nullptr) {
        for (size_t j = 0; j < i; ++j) std::free(arr[j].range);
        std::free(arr);
        throw std::bad_alloc();
      }
      std::memcpy(t.range, s.ranges.data(), sizeof(float) * s.ranges.size());
    }
  }
  *list = arr;
  *num = static_cast<int>(in.size());
}

void copy_text(char *dst, size_t cap, const std::string &src) {
  if (dst == nullptr) return;
  const size_t n = std::min(src.size(), cap - 1);
  std::memcpy(dst, src.data(), n);
  dst[n] = '\0';
}

// carmen_FILE helpers for the advance functions (no exceptions).
bool read_i32(carmen_FILE *fp, int32_t *v) {
  unsigned char b[4];
  if (carmen_fread(b, 1, 4, fp) != 4) return false;
  const uint32_t u = uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  std::memcpy(v, &u, 4);
  return true;
}

// Rewinds and reads past the comments and the id; false if they are not there.
bool skip_to_first_chunk(carmen_FILE *fp) {
  if (carmen_fseek(fp, 0, SEEK_SET) != 0) return false;
  int c;
  while ((c = carmen_fgetc(fp)) == '#') {
    while ((c = carmen_fgetc(fp)) != EOF && c != '\n') {
    }
    if (c == EOF) return false;
  }
  if (c == EOF) return false;
  const std::string id = std::string(CARMEN_MAP_LABEL) + CARMEN_MAP_VERSION;
  char rest[16];
  if (static_cast<char>(c) != id[0]) return false;
  if (carmen_fread(rest, 1, 16, fp) != 16) return false;
  return std::memcmp(rest, id.data() + 1, 16) == 0;
}

int advance(carmen_FILE *fp, int specific_chunk, const char *chunk_name) {
  if (fp == nullptr || !skip_to_first_chunk(fp)) return -1;
  while (true) {
    const int type = carmen_fgetc(fp);
    if (type == EOF) return -1;
    const long after_type = carmen_ftell(fp);
    const long at_type = after_type - 1;
    int32_t size;
    if (!read_i32(fp, &size) || size < 10) return -1;
    long skip = size;
    if ((type & ~CARMEN_MAP_NAMED_CHUNK_FLAG) == specific_chunk) {
      if (chunk_name == nullptr) return carmen_fseek(fp, at_type, SEEK_SET) == 0 ? 0 : -1;
      if (type & CARMEN_MAP_NAMED_CHUNK_FLAG) {
        char desc[10];
        if (carmen_fread(desc, 1, 10, fp) != 10) return -1;
        skip -= 10;
        std::string name;
        int c;
        while (skip > 0 && (c = carmen_fgetc(fp)) != EOF) {
          --skip;
          if (c == 0) break;
          name.push_back(static_cast<char>(c));
          if (name.size() > 4096) return -1;
        }
        if (name == chunk_name) return carmen_fseek(fp, at_type, SEEK_SET) == 0 ? 0 : -1;
      }
    }
    if (carmen_fseek(fp, skip, SEEK_CUR) != 0) return -1;
  }
}

// The writers, named or not (name NULL or empty: an unnamed chunk).
int write_gridmap(const char *fn, carmen_FILE *fp, const char *name, float **prob, int size_x, int size_y,
                  double resolution) {
  return guarded(fn, nullptr, [&] {
    return write_bytes(
        fp, carmen::encode_gridmap_chunk(grid_from(prob, size_x, size_y, resolution), name ? name : ""), fn);
  });
}

int write_places(const char *fn, carmen_FILE *fp, const char *name, carmen_place_p places, int num_places) {
  return guarded(fn, nullptr, [&] {
    return write_bytes(fp, carmen::encode_places_chunk(places_from(places, num_places), name ? name : ""),
                       fn);
  });
}

int write_offlimits(const char *fn, carmen_FILE *fp, const char *name, carmen_offlimits_p list, int n) {
  return guarded(fn, nullptr, [&] {
    return write_bytes(fp, carmen::encode_offlimits_chunk(offlimits_from(list, n), name ? name : ""), fn);
  });
}

int write_scans(const char *fn, carmen_FILE *fp, const char *name, carmen_laser_scan_p scans, int n) {
  return guarded(fn, nullptr, [&] {
    return write_bytes(fp, carmen::encode_laserscans_chunk(scans_from(scans, n), name ? name : ""), fn);
  });
}

int write_offset(const char *fn, carmen_FILE *fp, const char *name, const carmen_global_offset_t *offset) {
  return guarded(fn, nullptr, [&] {
    if (offset == nullptr) throw std::invalid_argument("no offset given (NULL)");
    const carmen::GlobalOffset o{offset->x, offset->y, offset->theta};
    return write_bytes(fp, carmen::encode_global_offset_chunk(o, name ? name : ""), fn);
  });
}

}  // namespace

extern "C" {

// ---------------------------------------------------------------------------
// Writers
// ---------------------------------------------------------------------------
int carmen_map_write_comment_chunk(carmen_FILE *fp, int size_x, int size_y, double resolution,
                                   const char *origin, const char *description) {
  const char *const fn = __func__;
  return guarded(fn, nullptr, [&] {
    const char *user = std::getenv("USER");
    const auto lines = carmen::standard_map_comments(size_x, size_y, resolution, origin ? origin : "",
                                                     description ? description : "", user ? user : "unknown",
                                                     static_cast<int64_t>(std::time(nullptr)));
    return write_bytes(fp, carmen::encode_comment_lines(lines), fn);
  });
}

int carmen_map_write_id(carmen_FILE *fp) { return write_bytes(fp, carmen::encode_map_id(), __func__); }

static int write_creator(const char *fn, carmen_FILE *fp, const char *name, const char *origin,
                         const char *description) {
  return guarded(fn, nullptr, [&] {
    carmen::CreatorInfo c;
    const char *user = std::getenv("USER");
    c.user = user ? user : "unknown";
    c.origin = origin ? origin : "";
    c.description = description ? description : "";
    c.time = static_cast<int64_t>(std::time(nullptr));
    c.time_bytes = static_cast<int>(sizeof(time_t));
    return write_bytes(fp, carmen::encode_creator_chunk(c, name ? name : ""), fn);
  });
}
int carmen_map_write_creator_chunk(carmen_FILE *fp, const char *origin, const char *description) {
  return write_creator(__func__, fp, nullptr, origin, description);
}
int carmen_map_write_named_creator_chunk(carmen_FILE *fp, const char *name, const char *origin,
                                         const char *description) {
  if (name == nullptr || *name == '\0') {
    report(__func__, "a named chunk needs a non-empty name");
    return -1;
  }
  return write_creator(__func__, fp, name, origin, description);
}

int carmen_map_write_named_gridmap_chunk(carmen_FILE *fp, const char *name, float **prob, int size_x,
                                         int size_y, double resolution) {
  return write_gridmap(__func__, fp, name, prob, size_x, size_y, resolution);
}
int carmen_map_write_gridmap_chunk(carmen_FILE *fp, float **prob, int size_x, int size_y, double resolution) {
  return write_gridmap(__func__, fp, nullptr, prob, size_x, size_y, resolution);
}

int carmen_map_write_named_places_chunk(carmen_FILE *fp, const char *name, carmen_place_p places,
                                        int num_places) {
  return write_places(__func__, fp, name, places, num_places);
}
int carmen_map_write_places_chunk(carmen_FILE *fp, carmen_place_p places, int num_places) {
  return write_places(__func__, fp, nullptr, places, num_places);
}

int carmen_map_write_named_offlimits_chunk(carmen_FILE *fp, const char *name,
                                           carmen_offlimits_p offlimits_list, int num_offlimits_items) {
  return write_offlimits(__func__, fp, name, offlimits_list, num_offlimits_items);
}
int carmen_map_write_offlimits_chunk(carmen_FILE *fp, carmen_offlimits_p offlimits_list,
                                     int num_offlimits_items) {
  return write_offlimits(__func__, fp, nullptr, offlimits_list, num_offlimits_items);
}

int carmen_map_write_named_laserscans_chunk(carmen_FILE *fp, const char *name, carmen_laser_scan_p scan_list,
                                            int num_scans) {
  return write_scans(__func__, fp, name, scan_list, num_scans);
}
int carmen_map_write_laserscans_chunk(carmen_FILE *fp, carmen_laser_scan_p scan_list, int num_scans) {
  return write_scans(__func__, fp, nullptr, scan_list, num_scans);
}

int carmen_map_write_named_global_offset_chunk(carmen_FILE *fp, const char *name,
                                               carmen_global_offset_t *global_offset) {
  return write_offset(__func__, fp, name, global_offset);
}
int carmen_map_write_global_offset_chunk(carmen_FILE *fp, carmen_global_offset_t *global_offset) {
  return write_offset(__func__, fp, nullptr, global_offset);
}

int carmen_map_write_all(carmen_FILE *fp, float **prob, int size_x, int size_y, double resolution,
                         const char *comment_origin, const char *comment_description,
                         const char *creator_origin, const char *creator_description, carmen_place_p places,
                         int num_places, carmen_offlimits_p offlimits_list, int offlimits_num_items,
                         carmen_laser_scan_p scan_list, int num_scans) {
  if (carmen_map_write_comment_chunk(fp, size_x, size_y, resolution, comment_origin, comment_description) <
          0 ||
      carmen_map_write_id(fp) < 0 ||
      carmen_map_write_creator_chunk(fp, creator_origin, creator_description) < 0 ||
      carmen_map_write_gridmap_chunk(fp, prob, size_x, size_y, resolution) < 0) {
    return -1;
  }
  if (num_places > 0 && carmen_map_write_places_chunk(fp, places, num_places) < 0) return -1;
  if (offlimits_num_items > 0 &&
      carmen_map_write_offlimits_chunk(fp, offlimits_list, offlimits_num_items) < 0) {
    return -1;
  }
  if (num_scans > 0 && carmen_map_write_laserscans_chunk(fp, scan_list, num_scans) < 0) return -1;
  return 0;
}

// ---------------------------------------------------------------------------
// Readers
// ---------------------------------------------------------------------------
static int read_gridmap(const char *fn, const char *filename, const char *chunk_name, carmen_map_p map) {
  return guarded(fn, filename, [&] {
    if (map == nullptr) throw std::invalid_argument("no map given (NULL)");
    const carmen::MapFile m = read_file(filename);
    const carmen::GridMap *g =
        chunk_name ? find_named<carmen::GridMap>(m, chunk_name) : (m.gridmap ? &*m.gridmap : nullptr);
    if (g == nullptr) missing(filename, "GRIDMAP");
    fill_map(*g, chunk_name ? chunk_name : filename, map);
    return 0;
  });
}
int carmen_map_read_named_gridmap_chunk(const char *filename, const char *chunk_name, carmen_map_p map) {
  return read_gridmap(__func__, filename, chunk_name, map);
}
int carmen_map_read_gridmap_chunk(const char *filename, carmen_map_p map) {
  return read_gridmap(__func__, filename, nullptr, map);
}

static int read_gridmap_config(const char *fn, const char *filename, const char *chunk_name,
                               carmen_map_config_p config) {
  return guarded(fn, filename, [&] {
    if (config == nullptr) throw std::invalid_argument("no config given (NULL)");
    const carmen::MapFile m = read_file(filename);
    const carmen::GridMap *g =
        chunk_name ? find_named<carmen::GridMap>(m, chunk_name) : (m.gridmap ? &*m.gridmap : nullptr);
    if (g == nullptr && chunk_name) missing_named(filename, "GRIDMAP", chunk_name);
    if (g == nullptr) missing(filename, "GRIDMAP");
    fill_config(*g, chunk_name ? chunk_name : filename, config);
    return 0;
  });
}
int carmen_map_read_gridmap_config(const char *filename, carmen_map_config_p config) {
  return read_gridmap_config(__func__, filename, nullptr, config);
}
int carmen_map_read_named_gridmap_config(const char *filename, const char *chunk_name,
                                         carmen_map_config_p config) {
  if (chunk_name == nullptr) return read_gridmap_config(__func__, filename, "", config);
  return read_gridmap_config(__func__, filename, chunk_name, config);
}

static void copy_creator(const carmen::CreatorInfo &c, time_t *creation_time, char *username, char *origin,
                         char *description) {
  if (creation_time != nullptr) *creation_time = static_cast<time_t>(c.time);
  copy_text(username, 11, c.user);
  copy_text(origin, 81, c.origin);
  copy_text(description, 81, c.description);
}

int carmen_map_read_creator_chunk(const char *filename, time_t *creation_time, char *username, char *origin,
                                  char *description) {
  return guarded(__func__, filename, [&] {
    const carmen::MapFile m = read_file(filename);
    if (!m.creator) missing(filename, "CREATOR");
    if (m.old_style_creator) std::fprintf(stderr, "%s: old-style map (creator chunk code 0)\n", filename);
    copy_creator(*m.creator, creation_time, username, origin, description);
    return 0;
  });
}

// Old-style (code 0) creators have no name, so only a named CREATOR chunk
// answers here.
int carmen_map_read_named_creator_chunk(const char *filename, const char *chunk_name, time_t *creation_time,
                                        char *username, char *origin, char *description) {
  return guarded(__func__, filename, [&] {
    const carmen::MapFile m = read_file(filename);
    const carmen::CreatorInfo *c = find_named<carmen::CreatorInfo>(m, chunk_name);
    if (c == nullptr) missing_named(filename, "CREATOR", chunk_name);
    copy_creator(*c, creation_time, username, origin, description);
    return 0;
  });
}

static int read_places(const char *fn, const char *filename, const char *chunk_name,
                       carmen_map_placelist_p places) {
  return guarded(fn, filename, [&] {
    if (places == nullptr) throw std::invalid_argument("no place list given (NULL)");
    const carmen::MapFile m = read_file(filename);
    const carmen::PlaceList *p =
        chunk_name ? find_named<carmen::PlaceList>(m, chunk_name) : (m.places ? &*m.places : nullptr);
    if (p == nullptr) missing(filename, "PLACES");
    fill_places(*p, places);
    return 0;
  });
}
int carmen_map_read_named_places_chunk(const char *filename, const char *chunk_name,
                                       carmen_map_placelist_p places) {
  return read_places(__func__, filename, chunk_name, places);
}
int carmen_map_read_places_chunk(const char *filename, carmen_map_placelist_p places) {
  return read_places(__func__, filename, nullptr, places);
}

static int read_offlimits(const char *fn, const char *filename, const char *chunk_name,
                          carmen_offlimits_p *offlimits_list, int *list_length) {
  return guarded(fn, filename, [&] {
    if (offlimits_list == nullptr || list_length == nullptr)
      throw std::invalid_argument("NULL output argument");
    const carmen::MapFile m = read_file(filename);
    const carmen::OffLimits *o =
        chunk_name ? find_named<carmen::OffLimits>(m, chunk_name) : (m.offlimits ? &*m.offlimits : nullptr);
    if (o == nullptr) missing(filename, "OFFLIMITS");
    fill_offlimits(*o, offlimits_list, list_length);
    return 0;
  });
}
int carmen_map_read_named_offlimits_chunk(const char *filename, const char *chunk_name,
                                          carmen_offlimits_p *offlimits_list, int *list_length) {
  return read_offlimits(__func__, filename, chunk_name, offlimits_list, list_length);
}
int carmen_map_read_offlimits_chunk(const char *filename, carmen_offlimits_p *offlimits_list,
                                    int *list_length) {
  return read_offlimits(__func__, filename, nullptr, offlimits_list, list_length);
}

static int read_laserscans(const char *fn, const char *filename, const char *chunk_name,
                           carmen_laser_scan_p *scan_list, int *num_scans) {
  return guarded(fn, filename, [&] {
    if (scan_list == nullptr || num_scans == nullptr) throw std::invalid_argument("NULL output argument");
    const carmen::MapFile m = read_file(filename);
    const carmen::LaserScanList *s = chunk_name ? find_named<carmen::LaserScanList>(m, chunk_name)
                                                : (m.laserscans ? &*m.laserscans : nullptr);
    if (s == nullptr) missing(filename, "LASERSCANS");
    fill_scans(*s, scan_list, num_scans);
    return 0;
  });
}
int carmen_map_read_named_laserscans_chunk(const char *filename, const char *chunk_name,
                                           carmen_laser_scan_p *scan_list, int *num_scans) {
  return read_laserscans(__func__, filename, chunk_name, scan_list, num_scans);
}
int carmen_map_read_laserscans_chunk(const char *filename, carmen_laser_scan_p *scan_list, int *num_scans) {
  return read_laserscans(__func__, filename, nullptr, scan_list, num_scans);
}

static int read_global_offset(const char *fn, const char *filename, const char *chunk_name,
                              carmen_global_offset_p global_offset) {
  return guarded(fn, filename, [&] {
    if (global_offset == nullptr) throw std::invalid_argument("no offset given (NULL)");
    const carmen::MapFile m = read_file(filename);
    const carmen::GlobalOffset *o =
        chunk_name ? find_named<carmen::GlobalOffset>(m, chunk_name) : (m.offset ? &*m.offset : nullptr);
    if (o == nullptr) missing(filename, "OFFSET");
    global_offset->x = o->x;
    global_offset->y = o->y;
    global_offset->theta = o->theta;
    return 0;
  });
}
int carmen_map_read_named_global_offset_chunk(const char *filename, const char *chunk_name,
                                              carmen_global_offset_p global_offset) {
  return read_global_offset(__func__, filename, chunk_name, global_offset);
}
int carmen_map_read_global_offset_chunk(const char *filename, carmen_global_offset_p global_offset) {
  return read_global_offset(__func__, filename, nullptr, global_offset);
}

// ---------------------------------------------------------------------------
// Utilities
// ---------------------------------------------------------------------------
int carmen_map_file(const char *filename) {
  return filename != nullptr && carmen::is_map_file(filename) ? 1 : 0;
}

int carmen_map_named_chunk_exists(const char *filename, int specific_chunk, const char *chunk_name) {
  const int rc = guarded(__func__, filename, [&] {
    if (filename == nullptr) throw std::invalid_argument("no file name given");
    for (const carmen::ChunkInfo &c : carmen::list_map_chunks(filename)) {
      if (c.base_type() != specific_chunk) continue;
      if (chunk_name != nullptr && (!c.named() || c.name != chunk_name)) continue;
      return static_cast<int>(c.size);
    }
    return 0;
  });
  return rc < 0 ? 0 : rc;
}
int carmen_map_chunk_exists(const char *filename, int specific_chunk) {
  return carmen_map_named_chunk_exists(filename, specific_chunk, nullptr);
}

int carmen_map_advance_to_chunk(carmen_FILE *fp, int specific_chunk) {
  return advance(fp, specific_chunk, nullptr);
}

int carmen_map_advance_to_named_chunk(carmen_FILE *fp, int specific_chunk, const char *chunk_name) {
  if (chunk_name == nullptr) return -1;
  return advance(fp, specific_chunk, chunk_name);
}

}  // extern "C"
