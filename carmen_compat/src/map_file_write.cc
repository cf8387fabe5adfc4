// CARMEN map files: the encoders and the atomic writer (map_file.h).
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"
#include "carmen_compat/file_names.h"
#include "carmen_compat/map_file.h"
#include "gzip_write.h"
#include "map_file_bytes.h"

namespace carmen {
namespace {

using namespace map_bytes;

constexpr int kCommentTextMax = 97;  // '#' + 97 + '\n' fits CARMEN's fgets(.., 100)

// A fixed-width text field: cut to `width`, padded with `pad`.
void put_field(std::string &s, const std::string &text, size_t width, char pad) {
  const size_t n = std::min(text.size(), width);
  s.append(text, 0, n);
  s.append(width - n, pad);
}

int32_t checked_count(size_t n, const char *what) {
  if (n > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    throw std::invalid_argument(std::string("too many ") + what + " for a CARMEN map chunk");
  }
  return static_cast<int32_t>(n);
}

// ---------------------------------------------------------------------------
// Encoding
// ---------------------------------------------------------------------------
std::string chunk_bytes(int type, bool named, const std::string &name, const std::string &payload) {
  if (named && name.find('\0') != std::string::npos) {
    throw std::invalid_argument("a chunk name may not contain a NUL byte");
  }
  const uint64_t size = 10 + (named ? name.size() + 1 : 0) + payload.size();
  if (size > static_cast<uint64_t>(std::numeric_limits<int32_t>::max())) {
    throw std::invalid_argument("the " + chunk_type_name(type) + " chunk would be " + std::to_string(size) +
                                " bytes: over the 2 GiB a CARMEN chunk can hold");
  }
  std::string s;
  s.reserve(static_cast<size_t>(size) + 5);
  s.push_back(static_cast<char>((type & 0x7f) | (named ? kNamedChunkFlag : 0)));
  put_i32(s, static_cast<int32_t>(size));
  s += chunk_description(type);
  if (named) {
    s += name;
    s.push_back('\0');
  }
  s += payload;
  return s;
}

std::string gridmap_payload(const GridMap &g) {
  if (g.size_x <= 0 || g.size_y <= 0) {
    throw std::invalid_argument("gridmap size " + std::to_string(g.size_x) + " x " +
                                std::to_string(g.size_y) + " is not positive");
  }
  if (g.cells.size() != size_t(g.size_x) * size_t(g.size_y)) {
    throw std::invalid_argument("gridmap has " + std::to_string(g.cells.size()) + " cells, size says " +
                                std::to_string(size_t(g.size_x) * size_t(g.size_y)));
  }
  if (g.cells.size() > (size_t{1} << 29)) {
    throw std::invalid_argument("gridmap of " + std::to_string(g.cells.size()) +
                                " cells is too large for a CARMEN map chunk");
  }
  std::string s;
  s.reserve(12 + 4 * g.cells.size());
  put_i32(s, g.size_x);
  put_i32(s, g.size_y);
  put_f32(s, static_cast<float>(g.resolution));
  if (host_is_little_endian()) {
    s.append(reinterpret_cast<const char *>(g.cells.data()), 4 * g.cells.size());
  } else {
    for (float v : g.cells) put_f32(s, v);
  }
  return s;
}

std::string creator_payload(const CreatorInfo &c) {
  if (c.time_bytes != 4 && c.time_bytes != 8) {
    throw std::invalid_argument("creator time width must be 4 or 8 bytes, not " +
                                std::to_string(c.time_bytes));
  }
  std::string s;
  put_field(s, c.user, 10, ' ');
  if (c.time_bytes == 4) {
    put_i32(s, static_cast<int32_t>(c.time));  // wraps after 2038, as a 32-bit time_t would
  } else {
    uint64_t u;
    std::memcpy(&u, &c.time, 8);
    put_u64(s, u);
  }
  put_field(s, c.origin, 80, ' ');
  put_field(s, c.description, 80, ' ');
  return s;
}

std::string offset_payload(const GlobalOffset &o) {
  std::string s;
  put_f64(s, o.x);
  put_f64(s, o.y);
  put_f64(s, o.theta);
  return s;
}

std::string places_payload(const PlaceList &places) {
  std::string s;
  put_i32(s, checked_count(places.size(), "places"));
  for (const Place &p : places) {
    if (p.type != kNamedPosition && p.type != kNamedPose && p.type != kLocalizationInit) {
      throw std::invalid_argument("place \"" + p.name + "\" has unknown type " + std::to_string(p.type));
    }
    put_i32(s, p.type);
    put_field(s, p.name, 20, ' ');  // space-padded, as CARMEN's write_fixed_string
    put_f32(s, static_cast<float>(p.x));
    put_f32(s, static_cast<float>(p.y));
    if (p.type != kNamedPosition) put_f32(s, static_cast<float>(p.theta));
    if (p.type == kLocalizationInit) {
      put_f32(s, static_cast<float>(p.x_std));
      put_f32(s, static_cast<float>(p.y_std));
      put_f32(s, static_cast<float>(p.theta_std));
    }
  }
  return s;
}

std::string offlimits_payload(const OffLimits &o) {
  std::string s;
  put_i32(s, checked_count(o.points.size(), "off-limits points"));
  for (const auto &p : o.points) {
    put_i32(s, p.x);
    put_i32(s, p.y);
  }
  for (const auto *list : {&o.lines, &o.rects}) {
    put_i32(s, checked_count(list->size(), "off-limits items"));
    for (const auto &l : *list) {
      put_i32(s, l.x1);
      put_i32(s, l.y1);
      put_i32(s, l.x2);
      put_i32(s, l.y2);
    }
  }
  return s;
}

std::string laserscans_payload(const LaserScanList &scans) {
  std::string s;
  put_i32(s, checked_count(scans.size(), "laser scans"));
  for (const LaserScan &sc : scans) {
    put_f32(s, static_cast<float>(sc.x));
    put_f32(s, static_cast<float>(sc.y));
    put_f32(s, static_cast<float>(sc.theta));
    put_i32(s, checked_count(sc.ranges.size(), "readings"));
    for (float r : sc.ranges) put_f32(s, r);
  }
  return s;
}

struct PayloadEncoder {
  std::pair<int, std::string> operator()(const GridMap &g) const {
    return {kGridmapChunk, gridmap_payload(g)};
  }
  std::pair<int, std::string> operator()(const OffLimits &o) const {
    return {kOfflimitsChunk, offlimits_payload(o)};
  }
  std::pair<int, std::string> operator()(const PlaceList &p) const {
    return {kPlacesChunk, places_payload(p)};
  }
  std::pair<int, std::string> operator()(const LaserScanList &l) const {
    return {kLaserscansChunk, laserscans_payload(l)};
  }
  std::pair<int, std::string> operator()(const CreatorInfo &c) const {
    return {kCreatorChunk, creator_payload(c)};
  }
  std::pair<int, std::string> operator()(const GlobalOffset &o) const {
    return {kGlobalOffsetChunk, offset_payload(o)};
  }
};

// Output to a temporary file, plain or gzip (gzip_write.h).
class Sink {
 public:
  Sink(AtomicOutput &out, bool gzip) : final_(out.final_path()) {
    if (gzip) {
      gz_.emplace(out.take_fd(), final_);  // in place: no allocation between taking the descriptor and owning it
    } else {
      fp_ = out.take_stdio();
    }
  }
  ~Sink() {
    if (fp_ != nullptr) std::fclose(fp_);
  }
  Sink(const Sink &) = delete;
  Sink &operator=(const Sink &) = delete;

  void write(const std::string &bytes) {
    if (gz_) {
      gz_->write(bytes.data(), bytes.size());
    } else if (std::fwrite(bytes.data(), 1, bytes.size(), fp_) != bytes.size()) {
      throw FileError(final_, std::string("write failed: ") + std::strerror(errno));
    }
  }
  void close() {
    if (gz_) {
      gz_->close();
      return;
    }
    const int rc = std::fclose(fp_);
    fp_ = nullptr;
    if (rc != 0) throw FileError(final_, std::string("write failed on close: ") + std::strerror(errno));
  }

 private:
  std::string final_;
  std::optional<gzip::GzipWriter> gz_;
  FILE *fp_ = nullptr;
};


}  // namespace

std::string encode_map_id() { return std::string(kMapLabel) + kMapVersion; }

std::string encode_comment_lines(const std::vector<std::string> &comments) {
  std::string s;
  for (const std::string &c : comments) {
    std::string line = c.substr(0, kCommentTextMax);
    for (char &ch : line) {
      if (ch == '\n' || ch == '\r' || ch == '\0') ch = ' ';
    }
    s += '#';
    s += line;
    s += '\n';
  }
  return s;
}

std::string encode_gridmap_chunk(const GridMap &map, const std::string &name) {
  return chunk_bytes(kGridmapChunk, !name.empty(), name, gridmap_payload(map));
}
std::string encode_creator_chunk(const CreatorInfo &creator, const std::string &name) {
  return chunk_bytes(kCreatorChunk, !name.empty(), name, creator_payload(creator));
}
std::string encode_global_offset_chunk(const GlobalOffset &offset, const std::string &name) {
  return chunk_bytes(kGlobalOffsetChunk, !name.empty(), name, offset_payload(offset));
}
std::string encode_places_chunk(const PlaceList &places, const std::string &name) {
  return chunk_bytes(kPlacesChunk, !name.empty(), name, places_payload(places));
}
std::string encode_offlimits_chunk(const OffLimits &offlimits, const std::string &name) {
  return chunk_bytes(kOfflimitsChunk, !name.empty(), name, offlimits_payload(offlimits));
}
std::string encode_laserscans_chunk(const LaserScanList &scans, const std::string &name) {
  return chunk_bytes(kLaserscansChunk, !name.empty(), name, laserscans_payload(scans));
}
std::string encode_chunk(const ChunkPayload &payload, const std::string &name) {
  auto [type, bytes] = std::visit(PayloadEncoder{}, payload);
  return chunk_bytes(type, !name.empty(), name, bytes);
}

void write_map_file(AtomicOutput &out, const MapFile &map) {
  // Encode everything first: an invalid MapFile throws before anything is written.
  std::vector<std::string> parts;
  parts.push_back(encode_comment_lines(map.comments) + encode_map_id());
  if (map.creator) parts.push_back(encode_creator_chunk(*map.creator));
  if (map.gridmap) parts.push_back(encode_gridmap_chunk(*map.gridmap));
  if (map.places) parts.push_back(encode_places_chunk(*map.places));
  if (map.offlimits) parts.push_back(encode_offlimits_chunk(*map.offlimits));
  if (map.laserscans) parts.push_back(encode_laserscans_chunk(*map.laserscans));
  if (map.offset) parts.push_back(encode_global_offset_chunk(*map.offset));
  for (const NamedChunk &nc : map.named) {
    if (nc.name.empty()) throw std::invalid_argument("a named chunk needs a non-empty name");
    parts.push_back(encode_chunk(nc.payload, nc.name));
  }
  Sink sink(out, is_gzip_name(out.final_path()));
  for (const std::string &p : parts) sink.write(p);
  sink.close();
}

void write_map_file(const std::string &path, const MapFile &map) {
  AtomicOutput out(path);
  write_map_file(out, map);
  out.commit();
}

// What asctime(localtime(&t)) gives, without its newline, by the C
// standard's definition of asctime (written out here: asctime's own buffer is
// shared and too short for years past 9999).
static std::string carmen_date(int64_t time) {
  static const char *const kDays[] = {"Sun", "Mon", "Tue", "Wed", "Thu", "Fri", "Sat"};
  static const char *const kMonths[] = {"Jan", "Feb", "Mar", "Apr", "May", "Jun",
                                        "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"};
  const std::time_t t = static_cast<std::time_t>(time);
  std::tm tm{};
  if (localtime_r(&t, &tm) == nullptr || tm.tm_wday < 0 || tm.tm_wday > 6 || tm.tm_mon < 0 || tm.tm_mon > 11)
    return "unknown";
  char date[96];
  std::snprintf(date, sizeof date, "%.3s %.3s%3d %.2d:%.2d:%.2d %d", kDays[tm.tm_wday], kMonths[tm.tm_mon],
                tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, 1900 + tm.tm_year);
  return date;
}

std::vector<std::string> standard_map_comments(int size_x, int size_y, double resolution,
                                               const std::string &origin, const std::string &description,
                                               const std::string &author, int64_t time) {
  const std::string rule(52, '#');  // encode_comment_lines adds the 53rd '#'
  char res[64];
  std::snprintf(res, sizeof res, "%.1f", resolution);
  // CARMEN writes no newline after the description: the "#" of its next line
  // ends that line, unless the description brings its own newline.
  std::string desc = description;
  const bool own_newline = !desc.empty() && desc.back() == '\n';
  if (own_newline) desc.pop_back();
  std::vector<std::string> lines = {
      rule,
      "",
      " Carnegie Mellon Robot Toolkit (CARMEN) map file",
      "",
      " Map author    : " + author,
      " Creation date : " + carmen_date(time),
      " Map size      : " + std::to_string(size_x) + " x " + std::to_string(size_y),
      std::string(" Resolution    : ") + res,
      " Origin        : " + origin,
      " Description   : " + desc + (own_newline ? "" : "#"),
  };
  if (own_newline) lines.push_back("");
  lines.push_back(rule);
  return lines;
}

std::string encode_raw_chunk(int type, const std::string &payload, const std::string &name) {
  return chunk_bytes(type, !name.empty(), name, payload);
}

}  // namespace carmen
