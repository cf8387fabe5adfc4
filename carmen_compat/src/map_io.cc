// CARMEN's map_io C API on top of carmen_compat/map_file.h.
#include "carmen/map_io.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <limits>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <variant>

#include "carmen_compat/error.h"
#include "carmen_compat/file_names.h"
#include "carmen_compat/map_file.h"
#include "carmen_stdio_results.h"
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

[[noreturn]] void missing(const char *filename, const char *what) {
  throw carmen::FileError(filename, std::string("has no ") + what + " chunk");
}

[[noreturn]] void missing_named(const char *filename, const char *what, const char *name) {
  throw carmen::FileError(filename, std::string("has no ") + what + " chunk named \"" +
                                        carmen::printable(name ? name : "") + "\"");
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

// The user CARMEN's writers name: getlogin(), or "UNKNOWN" when the process
// has no login name (no controlling terminal: cron, containers, daemons).
std::string login_name() {
  const char *user = getlogin();
  return user != nullptr ? user : "UNKNOWN";
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

// The payload of a chunk found by first_chunk (its type was asked for).
template <typename T>
const T &payload_of(const carmen::FoundChunk &c) {
  return std::get<T>(c.payload);
}

// A malloc()ed copy of `text`, as CARMEN's readers make for map_name.
char *malloc_copy(const char *text) {
  const size_t n = std::strlen(text) + 1;
  auto *copy = static_cast<char *>(std::malloc(n));
  if (copy == nullptr) throw std::bad_alloc();
  std::memcpy(copy, text, n);
  return copy;
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
  if (!carmen::checked_seek(fp, 0, SEEK_SET)) return false;
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
      if (chunk_name == nullptr) return carmen::checked_seek(fp, at_type, SEEK_SET) ? 0 : -1;
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
        if (name == chunk_name) return carmen::checked_seek(fp, at_type, SEEK_SET) ? 0 : -1;
      }
    }
    if (!carmen::checked_seek(fp, skip, SEEK_CUR)) return -1;
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

// What carmen_map_set_filename stored (CARMEN's map server would publish it).
std::mutex server_mutex;
std::string server_filename;

}  // namespace

extern "C" {

// ---------------------------------------------------------------------------
// Writers
// ---------------------------------------------------------------------------
// CARMEN's bytes (map_file.h, standard_map_comments): the author is
// getlogin(), or "UNKNOWN" when it has none; a NULL origin or description is
// written "(null)", as glibc's printf writes CARMEN's NULL.
// The bytes of CARMEN's comment lines and creator chunk, as its writers make them.
static std::string comment_bytes(int size_x, int size_y, double resolution, const char *origin,
                                 const char *description) {
  return carmen::encode_comment_lines(carmen::standard_map_comments(
      size_x, size_y, resolution, origin ? origin : "(null)", description ? description : "(null)", login_name(),
      static_cast<int64_t>(std::time(nullptr))));
}

static std::string creator_bytes(const char *name, const char *origin, const char *description) {
  carmen::CreatorInfo c;
  c.user = login_name();
  c.origin = origin ? origin : "";
  c.description = description ? description : "";
  c.time = static_cast<int64_t>(std::time(nullptr));
  c.time_bytes = static_cast<int>(sizeof(time_t));
  return carmen::encode_creator_chunk(c, name ? name : "");
}

int carmen_map_write_comment_chunk(carmen_FILE *fp, int size_x, int size_y, double resolution,
                                   const char *origin, const char *description) {
  const char *const fn = __func__;
  return guarded(fn, nullptr,
                 [&] { return write_bytes(fp, comment_bytes(size_x, size_y, resolution, origin, description), fn); });
}

int carmen_map_write_id(carmen_FILE *fp) { return write_bytes(fp, carmen::encode_map_id(), __func__); }

static int write_creator(const char *fn, carmen_FILE *fp, const char *name, const char *origin,
                         const char *description) {
  return guarded(fn, nullptr, [&] { return write_bytes(fp, creator_bytes(name, origin, description), fn); });
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
  // Every chunk is encoded before a byte is written: a map that cannot be
  // written (a 0 x 0 grid from a run that mapped nothing) leaves the file as
  // it was, not a comment and a header without a grid.
  const char *const fn = __func__;
  return guarded(fn, nullptr, [&] {
    std::string bytes = comment_bytes(size_x, size_y, resolution, comment_origin, comment_description) +
                        carmen::encode_map_id() + creator_bytes(nullptr, creator_origin, creator_description) +
                        carmen::encode_gridmap_chunk(grid_from(prob, size_x, size_y, resolution), "");
    if (num_places > 0) bytes += carmen::encode_places_chunk(places_from(places, num_places), "");
    if (offlimits_num_items > 0)
      bytes += carmen::encode_offlimits_chunk(offlimits_from(offlimits_list, offlimits_num_items), "");
    if (num_scans > 0) bytes += carmen::encode_laserscans_chunk(scans_from(scan_list, num_scans), "");
    return write_bytes(fp, bytes, fn);
  });
}

// ---------------------------------------------------------------------------
// Readers
// ---------------------------------------------------------------------------
// Every reader first clears its outputs, so that a failure never leaves them
// as the caller had them (often uninitialised): a program that then free()s
// or realloc()s them, as CARMEN's maptool does, gets NULL and zero counts.
// The chunk is found as CARMEN finds it (map_file.h, read_first_chunk): the
// first of its type, named or not, for the unnamed readers; the first named
// one called chunk_name for the named readers; chunks after it are not read.
// A missing chunk is reported on stderr where CARMEN reports it (gridmap,
// laser scans, creator, every named reader) and is a silent -1 where CARMEN's
// is (the unnamed places, off-limits and offset readers: maptool and the
// PPM writer ask for those on every map).

static void clear_config(carmen_map_config_p config) {
  config->x_size = 0;
  config->y_size = 0;
  config->resolution = 0;
  config->map_name = nullptr;
}

static void clear_map(carmen_map_p map) {
  clear_config(&map->config);
  map->complete_map = nullptr;
  map->map = nullptr;
}

// The reader's warnings (map_file.h: a gridmap cut short, CARMEN's
// off-limits layouts) on stderr, as "fn: FILE: warning: ...", like the
// warning about invalid cells.
static carmen::MapReadOptions warning_options(const char *fn) {
  carmen::MapReadOptions opts;
  opts.on_warning = [fn](const std::string &text) { std::fprintf(stderr, "%s: %s\n", fn, text.c_str()); };
  return opts;
}

// The first chunk of `type` (chunk_name NULL: named or not), or nullopt.
static std::optional<carmen::FoundChunk> first_chunk(const char *fn, const char *filename, int type,
                                                     const char *chunk_name) {
  carmen::map_io_detail::need_name(filename);
  const std::string name = chunk_name ? chunk_name : "";
  return carmen::read_first_chunk(filename, type, chunk_name ? &name : nullptr, warning_options(fn));
}

static void need_chunk_name(const char *chunk_name) {
  if (chunk_name == nullptr) throw std::invalid_argument("no chunk name given (NULL)");
}

[[noreturn]] static void missing_chunk(const char *filename, const char *what, const char *chunk_name) {
  if (chunk_name != nullptr) missing_named(filename, what, chunk_name);
  missing(filename, what);
}

// Cells that are none of CARMEN's values (damage) are returned as stored, as
// CARMEN returns them, with a warning on stderr naming the chunk: a map whose
// layout is intact is read, whatever its cells hold.
static void warn_invalid_cells(const char *fn, const char *filename, const carmen::FoundChunk &c) {
  const carmen::GridMap &g = payload_of<carmen::GridMap>(c);
  size_t bad = 0, first = 0;
  for (size_t i = 0; i < g.cells.size(); ++i) {
    if (!carmen::valid_cell_value(g.cells[i]) && bad++ == 0) first = i;
  }
  if (bad == 0) return;
  std::fprintf(stderr,
               "%s: %s: warning: the GRIDMAP chunk at byte %lld holds %zu invalid cell values of %zu (the first "
               "is cell (%zu, %zu) = %.9g): the map is damaged; its cells are returned as stored\n",
               fn, filename, static_cast<long long>(c.info.offset), bad, g.cells.size(),
               first / size_t(g.size_y), first % size_t(g.size_y), double(g.cells[first]));
}

static int read_gridmap(const char *fn, const char *filename, const char *chunk_name, bool named,
                        carmen_map_p map) {
  if (map != nullptr) clear_map(map);
  return guarded(fn, filename, [&] {
    if (map == nullptr) throw std::invalid_argument("no map given (NULL)");
    if (named) need_chunk_name(chunk_name);
    carmen::map_io_detail::need_name(filename);
    carmen::MapReadOptions opts = warning_options(fn);
    opts.check_cells = false;  // checked below, as a warning
    // A C caller cannot raise max_kept_bytes, and CARMEN reads any map. A
    // plain file's chunk sizes are checked against its size (and a pipe is
    // read in bounded pieces), so what is allocated is what the file holds:
    // no limit. A .gz can claim gigabytes in a few kilobytes: the limit
    // stays, and its message says what to do.
    const bool gzip = carmen::is_gzip_name(filename);
    if (!gzip) opts.max_kept_bytes = std::numeric_limits<uint64_t>::max();
    const std::string name = chunk_name ? chunk_name : "";
    std::optional<carmen::FoundChunk> c;
    try {
      c = carmen::read_first_chunk(filename, CARMEN_MAP_GRIDMAP_CHUNK, chunk_name ? &name : nullptr, opts);
    } catch (const carmen::FileError &e) {
      if (!gzip || e.code() != carmen::ErrorCode::TooLarge) throw;
      throw carmen::FileError(filename,
                              "its GRIDMAP chunk would take more than " + std::to_string(opts.max_kept_bytes >> 20) +
                                  " MiB, more than is read from a gzip file (whose size cannot vouch for the "
                                  "sizes it claims): gunzip the map and read the plain file, which has no such limit",
                              carmen::ErrorCode::TooLarge);
    }
    if (!c) missing_chunk(filename, "GRIDMAP", chunk_name);
    warn_invalid_cells(fn, filename, *c);
    fill_map(payload_of<carmen::GridMap>(*c), chunk_name ? chunk_name : filename, map);
    return 0;
  });
}
int carmen_map_read_named_gridmap_chunk(const char *filename, const char *chunk_name, carmen_map_p map) {
  return read_gridmap(__func__, filename, chunk_name, true, map);
}
int carmen_map_read_gridmap_chunk(const char *filename, carmen_map_p map) {
  return read_gridmap(__func__, filename, nullptr, false, map);
}

// Only the gridmap's header is read, as CARMEN's config reader does: the
// cells (and anything after the chunk) may be damaged.
static int read_gridmap_config(const char *fn, const char *filename, const char *chunk_name, bool named,
                               carmen_map_config_p config) {
  if (config != nullptr) clear_config(config);
  return guarded(fn, filename, [&] {
    if (config == nullptr) throw std::invalid_argument("no config given (NULL)");
    if (named) need_chunk_name(chunk_name);
    carmen::map_io_detail::need_name(filename);
    const std::string name = chunk_name ? chunk_name : "";
    const auto h = carmen::read_first_gridmap_header(filename, chunk_name ? &name : nullptr);
    if (!h) missing_chunk(filename, "GRIDMAP", chunk_name);
    char *copy = malloc_copy(chunk_name ? chunk_name : filename);
    config->x_size = h->size_x;
    config->y_size = h->size_y;
    config->resolution = h->resolution;
    config->map_name = copy;
    return 0;
  });
}
int carmen_map_read_gridmap_config(const char *filename, carmen_map_config_p config) {
  return read_gridmap_config(__func__, filename, nullptr, false, config);
}
int carmen_map_read_named_gridmap_config(const char *filename, const char *chunk_name,
                                         carmen_map_config_p config) {
  return read_gridmap_config(__func__, filename, chunk_name, true, config);
}

static void clear_creator(time_t *creation_time, char *username, char *origin, char *description) {
  if (creation_time != nullptr) *creation_time = 0;
  if (username != nullptr) *username = '\0';
  if (origin != nullptr) *origin = '\0';
  if (description != nullptr) *description = '\0';
}

static void copy_creator(const carmen::CreatorInfo &c, time_t *creation_time, char *username, char *origin,
                         char *description) {
  if (creation_time != nullptr) *creation_time = static_cast<time_t>(c.time);
  copy_text(username, 11, c.user);
  copy_text(origin, 81, c.origin);
  copy_text(description, 81, c.description);
}

// CARMEN's order: the first CREATOR chunk, else the first old-style (code 0)
// one, which is reported. Damage met while looking for a CREATOR chunk is
// reported only when there is no old-style creator to fall back to.
int carmen_map_read_creator_chunk(const char *filename, time_t *creation_time, char *username, char *origin,
                                  char *description) {
  const char *const fn = __func__;
  clear_creator(creation_time, username, origin, description);
  return guarded(fn, filename, [&] {
    std::optional<carmen::FoundChunk> c;
    try {
      c = first_chunk(fn, filename, CARMEN_MAP_CREATOR_CHUNK, nullptr);
    } catch (const carmen::FileError &) {
      std::optional<carmen::FoundChunk> old;
      try {
        old = first_chunk(fn, filename, CARMEN_MAP_CREATOR_OLD_CHUNK, nullptr);
      } catch (const carmen::FileError &) {
      }
      if (!old) throw;
      c = std::move(old);
    }
    if (!c) c = first_chunk(fn, filename, CARMEN_MAP_CREATOR_OLD_CHUNK, nullptr);
    if (!c) missing(filename, "CREATOR");
    if (c->info.base_type() == CARMEN_MAP_CREATOR_OLD_CHUNK)
      std::fprintf(stderr, "%s: old-style map (creator chunk code 0)\n", filename);
    copy_creator(payload_of<carmen::CreatorInfo>(*c), creation_time, username, origin, description);
    return 0;
  });
}

// Old-style (code 0) creators have no name, so only a named CREATOR chunk
// answers here.
int carmen_map_read_named_creator_chunk(const char *filename, const char *chunk_name, time_t *creation_time,
                                        char *username, char *origin, char *description) {
  const char *const fn = __func__;
  clear_creator(creation_time, username, origin, description);
  return guarded(fn, filename, [&] {
    need_chunk_name(chunk_name);
    const auto c = first_chunk(fn, filename, CARMEN_MAP_CREATOR_CHUNK, chunk_name);
    if (!c) missing_named(filename, "CREATOR", chunk_name);
    copy_creator(payload_of<carmen::CreatorInfo>(*c), creation_time, username, origin, description);
    return 0;
  });
}

static int read_places(const char *fn, const char *filename, const char *chunk_name, bool named,
                       carmen_map_placelist_p places) {
  if (places != nullptr) {
    places->places = nullptr;
    places->num_places = 0;
  }
  return guarded(fn, filename, [&] {
    if (places == nullptr) throw std::invalid_argument("no place list given (NULL)");
    if (named) need_chunk_name(chunk_name);
    const auto c = first_chunk(fn, filename, CARMEN_MAP_PLACES_CHUNK, chunk_name);
    if (!c && !named) return -1;  // silent, as CARMEN's
    if (!c) missing_named(filename, "PLACES", chunk_name);
    fill_places(payload_of<carmen::PlaceList>(*c), places);
    return 0;
  });
}
int carmen_map_read_named_places_chunk(const char *filename, const char *chunk_name,
                                       carmen_map_placelist_p places) {
  return read_places(__func__, filename, chunk_name, true, places);
}
int carmen_map_read_places_chunk(const char *filename, carmen_map_placelist_p places) {
  return read_places(__func__, filename, nullptr, false, places);
}

static int read_offlimits(const char *fn, const char *filename, const char *chunk_name, bool named,
                          carmen_offlimits_p *offlimits_list, int *list_length) {
  if (offlimits_list != nullptr) *offlimits_list = nullptr;
  if (list_length != nullptr) *list_length = 0;
  return guarded(fn, filename, [&] {
    if (offlimits_list == nullptr || list_length == nullptr)
      throw std::invalid_argument("NULL output argument");
    if (named) need_chunk_name(chunk_name);
    const auto c = first_chunk(fn, filename, CARMEN_MAP_OFFLIMITS_CHUNK, chunk_name);
    if (!c && !named) return -1;  // silent, as CARMEN's
    if (!c) missing_named(filename, "OFFLIMITS", chunk_name);
    fill_offlimits(payload_of<carmen::OffLimits>(*c), offlimits_list, list_length);
    return 0;
  });
}
int carmen_map_read_named_offlimits_chunk(const char *filename, const char *chunk_name,
                                          carmen_offlimits_p *offlimits_list, int *list_length) {
  return read_offlimits(__func__, filename, chunk_name, true, offlimits_list, list_length);
}
int carmen_map_read_offlimits_chunk(const char *filename, carmen_offlimits_p *offlimits_list,
                                    int *list_length) {
  return read_offlimits(__func__, filename, nullptr, false, offlimits_list, list_length);
}

static int read_laserscans(const char *fn, const char *filename, const char *chunk_name, bool named,
                           carmen_laser_scan_p *scan_list, int *num_scans) {
  if (scan_list != nullptr) *scan_list = nullptr;
  if (num_scans != nullptr) *num_scans = 0;
  return guarded(fn, filename, [&] {
    if (scan_list == nullptr || num_scans == nullptr) throw std::invalid_argument("NULL output argument");
    if (named) need_chunk_name(chunk_name);
    const auto c = first_chunk(fn, filename, CARMEN_MAP_LASERSCANS_CHUNK, chunk_name);
    if (!c) missing_chunk(filename, "LASERSCANS", chunk_name);
    fill_scans(payload_of<carmen::LaserScanList>(*c), scan_list, num_scans);
    return 0;
  });
}
int carmen_map_read_named_laserscans_chunk(const char *filename, const char *chunk_name,
                                           carmen_laser_scan_p *scan_list, int *num_scans) {
  return read_laserscans(__func__, filename, chunk_name, true, scan_list, num_scans);
}
int carmen_map_read_laserscans_chunk(const char *filename, carmen_laser_scan_p *scan_list, int *num_scans) {
  return read_laserscans(__func__, filename, nullptr, false, scan_list, num_scans);
}

static int read_global_offset(const char *fn, const char *filename, const char *chunk_name, bool named,
                              carmen_global_offset_p global_offset) {
  if (global_offset != nullptr) *global_offset = carmen_global_offset_t{0, 0, 0};
  return guarded(fn, filename, [&] {
    if (global_offset == nullptr) throw std::invalid_argument("no offset given (NULL)");
    if (named) need_chunk_name(chunk_name);
    const auto c = first_chunk(fn, filename, CARMEN_MAP_GLOBAL_OFFSET_CHUNK, chunk_name);
    if (!c && !named) return -1;  // silent, as CARMEN's
    if (!c) missing_named(filename, "OFFSET", chunk_name);
    const carmen::GlobalOffset &o = payload_of<carmen::GlobalOffset>(*c);
    global_offset->x = o.x;
    global_offset->y = o.y;
    global_offset->theta = o.theta;
    return 0;
  });
}
int carmen_map_read_named_global_offset_chunk(const char *filename, const char *chunk_name,
                                              carmen_global_offset_p global_offset) {
  return read_global_offset(__func__, filename, chunk_name, true, global_offset);
}
int carmen_map_read_global_offset_chunk(const char *filename, carmen_global_offset_p global_offset) {
  return read_global_offset(__func__, filename, nullptr, false, global_offset);
}

// ---------------------------------------------------------------------------
// Utilities
// ---------------------------------------------------------------------------
int carmen_map_file(const char *filename) {
  return filename != nullptr && carmen::is_map_file(filename) ? 1 : 0;
}

// Found as CARMEN's advance finds it: chunks after the one asked for are not
// read, so damage there does not hide it.
static int chunk_exists(const char *fn, const char *filename, int specific_chunk, const char *chunk_name) {
  const int rc = guarded(fn, filename, [&] {
    if (filename == nullptr) throw std::invalid_argument("no file name given");
    const std::string name = chunk_name ? chunk_name : "";
    const auto c = carmen::find_first_chunk(filename, specific_chunk, chunk_name ? &name : nullptr);
    return c ? static_cast<int>(c->size) : 0;
  });
  return rc < 0 ? 0 : rc;
}
int carmen_map_named_chunk_exists(const char *filename, int specific_chunk, const char *chunk_name) {
  return chunk_exists(__func__, filename, specific_chunk, chunk_name);
}
int carmen_map_chunk_exists(const char *filename, int specific_chunk) {
  return chunk_exists(__func__, filename, specific_chunk, nullptr);
}

// ---------------------------------------------------------------------------
// CARMEN's map-server calls (map_interface.c in CARMEN), without IPC
// ---------------------------------------------------------------------------
int carmen_map_initialize_ipc(void) {
  std::string name;
  {
    const std::lock_guard<std::mutex> lock(server_mutex);
    name = server_filename;
  }
  std::fprintf(stderr, "%s: no IPC in vasco_gpu: %s cannot be served to other processes\n", __func__,
               name.empty() ? "the map" : name.c_str());
  return -1;
}

void carmen_map_set_filename(const char *new_filename) {
  const std::lock_guard<std::mutex> lock(server_mutex);
  server_filename = new_filename ? new_filename : "";
}

void carmen_map_publish_update(void) {}

int carmen_map_advance_to_chunk(carmen_FILE *fp, int specific_chunk) {
  return advance(fp, specific_chunk, nullptr);
}

int carmen_map_advance_to_named_chunk(carmen_FILE *fp, int specific_chunk, const char *chunk_name) {
  if (chunk_name == nullptr) return -1;
  return advance(fp, specific_chunk, chunk_name);
}

}  // extern "C"
