// CARMEN's map_io C API, its writers (carmen_map_write_*): every chunk is
// encoded by map_file.h's encoders from the caller's C structs, checked
// before a byte is written.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <string>

#include "carmen/map_io.h"
#include "carmen_compat/map_file.h"
#include "map_io_support.h"

namespace {

using carmen::map_io_detail::guarded;
using carmen::map_io_detail::report;

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

}  // extern "C"
