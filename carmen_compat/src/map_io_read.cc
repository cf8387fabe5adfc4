// CARMEN's map_io C API, its readers (carmen_map_read_*): each finds its
// chunk with map_file.h's read_first_chunk and copies it into CARMEN's
// malloc()ed C structs.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <limits>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>

#include "carmen/map_io.h"
#include "carmen_compat/error.h"
#include "carmen_compat/file_names.h"
#include "carmen_compat/map_file.h"
#include "map_io_support.h"

namespace {

using carmen::map_io_detail::guarded;

[[noreturn]] void missing(const char *filename, const char *what) {
  throw carmen::FileError(filename, std::string("has no ") + what + " chunk");
}

[[noreturn]] void missing_named(const char *filename, const char *what, const char *name) {
  throw carmen::FileError(filename, std::string("has no ") + what + " chunk named \"" +
                                        carmen::printable(name ? name : "") + "\"");
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

}  // namespace

extern "C" {

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

}  // extern "C"
