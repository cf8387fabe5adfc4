// What mapconvert --info prints (mapconvert_info.h).
#include "mapconvert_info.h"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <limits>
#include <string>

namespace mapconvert {
namespace {

std::string quoted(const std::string &s) { return "\"" + s + "\""; }

// The grid's size, resolution, unknown fraction and value range.
void print_grid(const carmen::GridMap &g) {
  size_t unknown = 0, offlimits = 0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (float v : g.cells) {
    if (v == carmen::kUnknownCell) {
      ++unknown;
      continue;
    }
    if (v >= 2.0f) ++offlimits;
    lo = std::min(lo, double(v));
    hi = std::max(hi, double(v));
  }
  const size_t n = g.cells.size();
  std::printf("size: %d x %d cells\n", g.size_x, g.size_y);
  std::printf("resolution: %.9g m\n", g.resolution);
  std::printf("extent: %g x %g m\n", g.size_x * g.resolution, g.size_y * g.resolution);
  std::printf("unknown: %zu of %zu cells (%.2f%%)\n", unknown, n,
              n ? 100.0 * double(unknown) / double(n) : 0.0);
  if (unknown < n) {
    std::printf("known values: min %.9g max %.9g\n", lo, hi);
  } else {
    std::printf("known values: none\n");
  }
  if (offlimits > 0) std::printf("off-limits cells: %zu\n", offlimits);
}

}  // namespace

void print_info(const std::string &path, const carmen::MapFile &m, const char *format) {
  std::printf("file: %s\n", path.c_str());
  if (format != nullptr) std::printf("format: %s\n", format);
  if (format == nullptr) std::printf("comment lines: %zu\n", m.comments.size());
  if (format == nullptr) std::printf("chunks: %zu\n", m.chunks.size());
  for (const carmen::ChunkInfo &c : m.chunks) {
    std::printf("  %-10s %10d bytes at byte %lld%s%s\n", carmen::chunk_type_name(c.type).c_str(), c.size,
                static_cast<long long>(c.offset), c.named() ? (" named " + quoted(c.name)).c_str() : "",
                c.used ? "" : " (skipped)");
  }
  if (m.creator) {
    const carmen::CreatorInfo &c = *m.creator;
    char date[64] = "?";
    const std::time_t t = static_cast<std::time_t>(c.time);
    std::tm tm_utc;
    if (gmtime_r(&t, &tm_utc) != nullptr) std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S UTC", &tm_utc);
    std::printf("creator: user %s, time %s (%d-byte time_t%s), origin %s, description %s\n",
                quoted(c.user).c_str(), date, c.time_bytes, m.old_style_creator ? ", old-style chunk" : "",
                quoted(c.origin).c_str(), quoted(c.description).c_str());
  }
  if (m.offset) std::printf("offset: x %g y %g theta %g\n", m.offset->x, m.offset->y, m.offset->theta);
  if (m.places) std::printf("places: %zu\n", m.places->size());
  if (m.offlimits) {
    std::printf("offlimits: %zu points, %zu lines, %zu rectangles\n", m.offlimits->points.size(),
                m.offlimits->lines.size(), m.offlimits->rects.size());
  }
  if (m.laserscans) std::printf("laserscans: %zu\n", m.laserscans->size());
  if (m.unknown_chunks > 0) std::printf("skipped chunks: %d\n", m.unknown_chunks);
  if (!m.gridmap) {
    std::printf("gridmap: none\n");
    return;
  }
  print_grid(*m.gridmap);
}

}  // namespace mapconvert
