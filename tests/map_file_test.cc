// carmen_compat/map_file.h: CARMEN map files, read and written.
#include "test_seed.h"
#include "carmen_compat/map_file.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <new>
#include <random>

#include "carmen/map_io.h"
#include "carmen_compat/error.h"
#include "map_test_support.h"

// ---------------------------------------------------------------------------
// Largest single allocation, to show that sizes claimed by a file are not
// allocated before the file proves it holds them. (Replaces the global
// operator new for this test program only; GCC cannot see that the
// replaced new and delete pair malloc with free, hence the pragma.)
// ---------------------------------------------------------------------------
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
namespace {
std::atomic<size_t> g_largest_alloc{0};
void note_alloc(size_t n) {
  size_t cur = g_largest_alloc.load(std::memory_order_relaxed);
  while (n > cur && !g_largest_alloc.compare_exchange_weak(cur, n, std::memory_order_relaxed)) {
  }
}
}  // namespace

void *operator new(size_t n) {
  note_alloc(n);
  if (void *p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void *operator new[](size_t n) {
  note_alloc(n);
  if (void *p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void *p) noexcept { std::free(p); }
void operator delete[](void *p) noexcept { std::free(p); }
void operator delete(void *p, size_t) noexcept { std::free(p); }
void operator delete[](void *p, size_t) noexcept { std::free(p); }

namespace {

using namespace maptest;
using carmen::FileError;
using carmen::MapFile;

constexpr size_t kAllocLimit = size_t{64} << 20;  // far below every claim used below

// Expects read_map_file(path) to throw a FileError whose text names the file
// and contains every one of `parts`.
void expect_rejected(const std::string &path, const std::vector<std::string> &parts,
                     const carmen::MapReadOptions &opts = {}) {
  try {
    carmen::read_map_file(path, opts);
    ADD_FAILURE() << path << " was accepted";
  } catch (const FileError &e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    for (const std::string &p : parts)
      EXPECT_NE(what.find(p), std::string::npos) << "no '" << p << "' in: " << what;
  } catch (const std::exception &e) {
    ADD_FAILURE() << path << ": wrong exception type: " << e.what();
  }
}

// A small map using every chunk type, with values exact in float.
MapFile sample_map() {
  MapFile m;
  m.comments = {"####", " Map author    : tester", "", " Description   : sample"};
  carmen::CreatorInfo c;
  c.user = "tester";
  c.origin = "unit test";
  c.description = "every chunk";
  c.time = 1234567890;
  c.time_bytes = 8;
  m.creator = c;
  carmen::GridMap g = carmen::GridMap::filled(3, 2, 0.25, -1.0f);
  g.at(0, 0) = 0.0f;
  g.at(1, 0) = 0.5f;
  g.at(2, 1) = 1.0f;
  g.at(1, 1) = 2.5f;  // an off-limits overlay value
  m.gridmap = g;
  m.offset = carmen::GlobalOffset{-12.5, 3.125, 0.7853981633974483};
  carmen::PlaceList places(3);
  places[0] = {carmen::kNamedPosition, "door", 1.5, -2.25, 0, 0, 0, 0};
  places[1] = {carmen::kNamedPose, "desk", 4.0, 5.0, 1.5, 0, 0, 0};
  places[2] = {carmen::kLocalizationInit, "start", 0.5, 0.25, -0.75, 0.125, 0.0625, 0.03125};
  m.places = places;
  carmen::OffLimits o;
  o.points = {{1, 2}, {-3, 4}};
  o.lines = {{0, 0, 10, 10}};
  o.rects = {{5, 6, 7, 8}, {-1, -2, 3, 4}};
  m.offlimits = o;
  carmen::LaserScan s1{1.0, 2.0, 0.5, {1.0f, 2.5f, 81.91f}};
  carmen::LaserScan s2{-1.0, 0.0, -0.25, {}};
  m.laserscans = carmen::LaserScanList{s1, s2};
  carmen::GridMap small = carmen::GridMap::filled(1, 2, 0.5, 0.25f);
  m.named.push_back({"coarse", small});
  m.named.push_back({"home", carmen::GlobalOffset{1.0, 2.0, 3.0}});
  m.named.push_back({"extra places", carmen::PlaceList{{carmen::kNamedPose, "x", 1, 2, 3, 0, 0, 0}}});
  m.named.push_back({"ol", carmen::OffLimits{{{9, 9}}, {}, {}}});
  m.named.push_back({"scans", carmen::LaserScanList{{0, 0, 0, {3.0f}}}});
  carmen::CreatorInfo c2 = c;
  c2.time_bytes = 4;
  c2.user = "other";
  m.named.push_back({"who", c2});
  return m;
}

void expect_same_map(const MapFile &a, const MapFile &b) {
  EXPECT_EQ(a.comments, b.comments);
  ASSERT_EQ(a.creator.has_value(), b.creator.has_value());
  if (a.creator) {
    EXPECT_EQ(a.creator->user, b.creator->user);
    EXPECT_EQ(a.creator->origin, b.creator->origin);
    EXPECT_EQ(a.creator->description, b.creator->description);
    EXPECT_EQ(a.creator->time, b.creator->time);
    EXPECT_EQ(a.creator->time_bytes, b.creator->time_bytes);
  }
  ASSERT_EQ(a.gridmap.has_value(), b.gridmap.has_value());
  if (a.gridmap) {
    EXPECT_EQ(a.gridmap->size_x, b.gridmap->size_x);
    EXPECT_EQ(a.gridmap->size_y, b.gridmap->size_y);
    EXPECT_EQ(a.gridmap->resolution, b.gridmap->resolution);
    EXPECT_EQ(a.gridmap->cells, b.gridmap->cells);
  }
  ASSERT_EQ(a.offset.has_value(), b.offset.has_value());
  if (a.offset) {
    EXPECT_EQ(a.offset->x, b.offset->x);
    EXPECT_EQ(a.offset->y, b.offset->y);
    EXPECT_EQ(a.offset->theta, b.offset->theta);
  }
  ASSERT_EQ(a.places.has_value(), b.places.has_value());
  if (a.places) {
    ASSERT_EQ(a.places->size(), b.places->size());
    for (size_t i = 0; i < a.places->size(); ++i) {
      const auto &p = (*a.places)[i];
      const auto &q = (*b.places)[i];
      EXPECT_EQ(p.type, q.type);
      EXPECT_EQ(p.name, q.name);
      EXPECT_EQ(p.x, q.x);
      EXPECT_EQ(p.y, q.y);
      EXPECT_EQ(p.theta, q.theta);
      EXPECT_EQ(p.x_std, q.x_std);
      EXPECT_EQ(p.y_std, q.y_std);
      EXPECT_EQ(p.theta_std, q.theta_std);
    }
  }
  ASSERT_EQ(a.offlimits.has_value(), b.offlimits.has_value());
  if (a.offlimits) {
    ASSERT_EQ(a.offlimits->points.size(), b.offlimits->points.size());
    for (size_t i = 0; i < a.offlimits->points.size(); ++i) {
      EXPECT_EQ(a.offlimits->points[i].x, b.offlimits->points[i].x);
      EXPECT_EQ(a.offlimits->points[i].y, b.offlimits->points[i].y);
    }
    auto same_segments = [](const std::vector<carmen::OffLimits::Segment> &u,
                            const std::vector<carmen::OffLimits::Segment> &v) {
      ASSERT_EQ(u.size(), v.size());
      for (size_t i = 0; i < u.size(); ++i) {
        EXPECT_EQ(u[i].x1, v[i].x1);
        EXPECT_EQ(u[i].y1, v[i].y1);
        EXPECT_EQ(u[i].x2, v[i].x2);
        EXPECT_EQ(u[i].y2, v[i].y2);
      }
    };
    same_segments(a.offlimits->lines, b.offlimits->lines);
    same_segments(a.offlimits->rects, b.offlimits->rects);
  }
  ASSERT_EQ(a.laserscans.has_value(), b.laserscans.has_value());
  if (a.laserscans) {
    ASSERT_EQ(a.laserscans->size(), b.laserscans->size());
    for (size_t i = 0; i < a.laserscans->size(); ++i) {
      EXPECT_EQ((*a.laserscans)[i].x, (*b.laserscans)[i].x);
      EXPECT_EQ((*a.laserscans)[i].y, (*b.laserscans)[i].y);
      EXPECT_EQ((*a.laserscans)[i].theta, (*b.laserscans)[i].theta);
      EXPECT_EQ((*a.laserscans)[i].ranges, (*b.laserscans)[i].ranges);
    }
  }
  ASSERT_EQ(a.named.size(), b.named.size());
  for (size_t i = 0; i < a.named.size(); ++i) {
    EXPECT_EQ(a.named[i].name, b.named[i].name);
    EXPECT_EQ(a.named[i].type(), b.named[i].type());
    // Compare the payloads through single-chunk maps.
    MapFile x, y;
    std::visit(
        [&](const auto &p) {
          using T = std::decay_t<decltype(p)>;
          const T &q = std::get<T>(b.named[i].payload);
          if constexpr (std::is_same_v<T, carmen::GridMap>) {
            x.gridmap = p;
            y.gridmap = q;
          } else if constexpr (std::is_same_v<T, carmen::OffLimits>) {
            x.offlimits = p;
            y.offlimits = q;
          } else if constexpr (std::is_same_v<T, carmen::PlaceList>) {
            x.places = p;
            y.places = q;
          } else if constexpr (std::is_same_v<T, carmen::LaserScanList>) {
            x.laserscans = p;
            y.laserscans = q;
          } else if constexpr (std::is_same_v<T, carmen::CreatorInfo>) {
            x.creator = p;
            y.creator = q;
          } else {
            x.offset = p;
            y.offset = q;
          }
        },
        a.named[i].payload);
    expect_same_map(x, y);
  }
}

// ---------------------------------------------------------------------------
// The real map
// ---------------------------------------------------------------------------
TEST(MapFile, FreiburgReadsAs300By300At10cm) {
  const std::string path = map_fixture("freiburg.map");
  const MapFile m = carmen::read_map_file(path);
  ASSERT_TRUE(m.gridmap);
  const carmen::GridMap &g = *m.gridmap;
  EXPECT_EQ(g.size_x, 300);
  EXPECT_EQ(g.size_y, 300);
  EXPECT_EQ(g.resolution, static_cast<double>(0.1f));
  ASSERT_EQ(g.cells.size(), 90000u);
  size_t unknown = 0;
  float lo = 2, hi = -2;
  for (float v : g.cells) {
    if (v == -1.0f) {
      ++unknown;
    } else {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  EXPECT_NEAR(double(unknown) / 90000.0, 0.497, 0.001);  // the fixture README's 49.7%
  EXPECT_NEAR(lo, 0.004, 1e-6);
  EXPECT_EQ(hi, 1.0f);
  EXPECT_TRUE(m.comments.empty());
  ASSERT_TRUE(m.creator);
  EXPECT_EQ(m.creator->user, "nickr");
  EXPECT_EQ(m.creator->origin, "bee2carmen");
  EXPECT_EQ(m.creator->description, "Created from freiburg.map");
  EXPECT_EQ(m.creator->time_bytes, 4);
  EXPECT_FALSE(m.offset);
  EXPECT_EQ(m.unknown_chunks, 0);
  ASSERT_EQ(m.chunks.size(), 2u);
  EXPECT_EQ(m.chunks[0].type, 32);
  EXPECT_EQ(m.chunks[0].offset, 17);
  EXPECT_EQ(m.chunks[0].size, 184);
  EXPECT_EQ(m.chunks[1].type, 1);
  EXPECT_EQ(m.chunks[1].offset, 17 + 5 + 184);
  EXPECT_EQ(m.chunks[1].size, 10 + 12 + 4 * 90000);
  EXPECT_EQ(m.chunks[1].description, "GRIDMAP   ");
}

TEST(MapFile, AllocationTrackerWorks) {
  // The allocation checks below mean something only if big allocations are seen.
  g_largest_alloc = 0;
  const MapFile m = carmen::read_map_file(map_fixture("freiburg.map"));
  EXPECT_GE(g_largest_alloc.load(), 90000 * sizeof(float));
}

TEST(MapFile, FreiburgCellsMatchTheRawBytes) {
  // Independent decoding: cells start after id (17), creator (5 + 184),
  // gridmap header (5 + 10 + 12); x-major.
  const std::string path = map_fixture("freiburg.map");
  const std::string raw = read_bytes(path);
  ASSERT_EQ(raw.size(), 17u + 189u + 5u + 360022u);
  const size_t cells_at = 17 + 189 + 5 + 10 + 12;
  EXPECT_EQ(read_i32(raw, 17 + 189 + 15), 300);
  unsigned long long raw_unknown = 0;
  for (size_t i = 0; i < 90000; ++i) raw_unknown += read_f32(raw, cells_at + 4 * i) == -1.0f;
  const carmen::GridMap g = *carmen::read_map_file(path).gridmap;
  size_t unknown = 0;
  for (float v : g.cells) unknown += v == -1.0f;
  EXPECT_EQ(unknown, raw_unknown);
  for (int x : {0, 57, 150, 299}) {
    for (int y : {0, 100, 151, 299}) {
      EXPECT_EQ(g.at(x, y), read_f32(raw, cells_at + 4 * (size_t(x) * 300 + size_t(y)))) << x << "," << y;
    }
  }
}

TEST(MapFile, FreiburgWrittenBackIsByteIdentical) {
  TempDir dir;
  const std::string path = map_fixture("freiburg.map");
  const MapFile m = carmen::read_map_file(path);
  carmen::write_map_file(dir.file("copy.map"), m);
  EXPECT_EQ(read_bytes(dir.file("copy.map")), read_bytes(path));
  carmen::write_map_file(dir.file("copy.map.gz"), m);
  EXPECT_EQ(gunzip_file(dir.file("copy.map.gz")), read_bytes(path));
  EXPECT_EQ(read_bytes(dir.file("copy.map.gz")).substr(0, 2), std::string("\x1f\x8b", 2));  // really gzip
}

// ---------------------------------------------------------------------------
// Damaged maps from CARMEN's data folder
// ---------------------------------------------------------------------------
TEST(MapFile, LongwoodRejectedForGarbageCells) {
  const std::string path = map_fixture("damaged/longwood.map.gz");
  expect_rejected(path, {"GRIDMAP", "invalid cell values", "damaged"});
  // Its layout is sound: without the value check it reads.
  carmen::MapReadOptions lax;
  lax.check_cells = false;
  const MapFile m = carmen::read_map_file(path, lax);
  ASSERT_TRUE(m.gridmap);
  EXPECT_EQ(m.gridmap->size_x, 536);
  EXPECT_EQ(m.gridmap->size_y, 379);
  EXPECT_EQ(m.comments.size(), 11u);
}

// nsh_level_3's GRIDMAP chunk is one byte short (a byte lost near cell
// (211, 223), the cells after it shifted): read as CARMEN reads it, the last
// cell's missing byte a zero and a warning saying so; the shifted cells are damage, which
// read_map_file refuses (mapconvert and mapdiff with it) and the C API
// returns with a warning.
TEST(MapFile, NshLevel3IsReadOneByteShortAndRefusedForItsShiftedCells) {
  const std::string path = map_fixture("damaged/nsh_level_3.map.gz");
  std::vector<std::string> warnings;
  carmen::MapReadOptions opts;
  opts.on_warning = [&](const std::string &w) { warnings.push_back(w); };
  expect_rejected(path, {"GRIDMAP", "invalid cell values", "(211, 223)"}, opts);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], path + ": warning: the GRIDMAP chunk at byte 540 is 1 byte short: it claims 1270074 "
                                "bytes but the file ends after 1270073 of them; its last 1 of 317513 cells "
                                "(x-major order) are missing and read as CARMEN's reader leaves them: zero "
                                "bytes (0, free), the first after the bytes that came");
  opts.check_cells = false;
  const MapFile m = carmen::read_map_file(path, opts);
  ASSERT_TRUE(m.gridmap);
  EXPECT_EQ(m.gridmap->size_x, 677);
  EXPECT_EQ(m.gridmap->size_y, 469);
  // The last cell: the file's last 3 bytes and a zero, as CARMEN's calloc()ed grid holds it.
  const std::string bytes = maptest::gunzip_file(path);
  EXPECT_EQ(m.gridmap->at(676, 468), maptest::cells_cut_short(bytes.substr(bytes.size() - 3) + '\x5a', 3)[0]);
  EXPECT_EQ(m.gridmap->at(0, 0), -1.0f);
  EXPECT_EQ(warnings.size(), 2u);
}

TEST(MapFile, ThickweanRejectedForItsHugeChunk) {
  g_largest_alloc = 0;
  expect_rejected(map_fixture("damaged/thickwean.map.gz"),
                  {"cut short", "claims 1342177280 bytes", "324950"});
  EXPECT_LT(g_largest_alloc.load(), kAllocLimit);
}

TEST(MapFile, Wean5300RejectedAsDoubleGzip) {
  expect_rejected(map_fixture("damaged/wean5300.map.gz"), {"gzip", "CARMENMAPFILEv020"});
}

// ---------------------------------------------------------------------------
// A GRIDMAP chunk cut short: the cells there, the rest unknown, a warning
// ---------------------------------------------------------------------------
// Reads `path` collecting the warnings.
MapFile read_warned(const std::string &path, std::vector<std::string> *warnings,
                    carmen::MapReadOptions opts = {}) {
  opts.on_warning = [warnings](const std::string &w) { warnings->push_back(w); };
  return carmen::read_map_file(path, opts);
}

void write_plain_or_gzip(const std::string &path, const std::string &bytes) {
  if (path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0) {
    gzip_to_file(path, bytes);
  } else {
    write_bytes(path, bytes);
  }
}

TEST(MapFileShortGridmap, MissingBytesAreZeroAsCarmensReaderLeavesThem) {
  TempDir dir;
  const std::vector<float> cells = {0.0f, 0.25f, 0.5f, 0.75f, 1.0f, 2.5f};  // 3 x 2, x-major
  std::string payload = i32(3) + i32(2) + f32(0.5f);
  for (float v : cells) payload += f32(v);
  // Cut by: a byte (the last cell half there), a cell, two cells and a
  // byte, every cell (the header alone).
  std::string cell_bytes;
  for (float v : cells) cell_bytes += f32(v);
  const struct {
    size_t cut;
    size_t missing;  // cells not wholly there
  } cases[] = {{1, 1}, {4, 1}, {9, 3}, {24, 6}};
  for (const bool named : {false, true}) {
    const std::string whole = chunk(1, "GRIDMAP", payload, "zone", named);
    const std::string where = std::string("the GRIDMAP chunk at byte 17 ") + (named ? "(named \"zone\") " : "");
    for (const auto &c : cases) {
      for (const char *ext : {".map", ".map.gz"}) {
        const std::string path = dir.file(std::string("short") + ext);
        write_plain_or_gzip(path, kId + whole.substr(0, whole.size() - c.cut));
        std::vector<std::string> warnings;
        const MapFile m = read_warned(path, &warnings);
        const carmen::GridMap &g = named ? std::get<carmen::GridMap>(m.named.at(0).payload) : *m.gridmap;
        ASSERT_EQ(g.cells.size(), cells.size());
        const std::vector<float> want = maptest::cells_cut_short(cell_bytes, cell_bytes.size() - c.cut);
        for (size_t i = 0; i < cells.size(); ++i) {
          EXPECT_EQ(g.cells[i], want[i]) << c.cut << " " << i;
          if (i < cells.size() - c.missing) {
            EXPECT_EQ(g.cells[i], cells[i]);
          } else if (i >= cells.size() - c.missing + (c.cut % 4 != 0)) {
            EXPECT_EQ(g.cells[i], 0.0f);
          }
        }
        ASSERT_EQ(warnings.size(), 1u);
        const int32_t size = read_i32(whole, 1);
        EXPECT_EQ(warnings[0], path + ": warning: " + where + "is " + std::to_string(c.cut) +
                                   (c.cut == 1 ? " byte" : " bytes") + " short: it claims " + std::to_string(size) +
                                   " bytes but the file ends after " + std::to_string(size - int32_t(c.cut)) +
                                   " of them; its last " + std::to_string(c.missing) +
                                   " of 6 cells (x-major order) are missing and read as CARMEN's reader leaves "
                                   "them: zero bytes (0, free)" +
                                   (c.cut % 4 != 0 ? ", the first after the bytes that came" : ""));
        // The other ways in find it whole, and the header scan passes it.
        const std::string zone = "zone";
        const auto found = carmen::read_first_chunk(path, carmen::kGridmapChunk, named ? &zone : nullptr);
        ASSERT_TRUE(found);
        EXPECT_EQ(std::get<carmen::GridMap>(found->payload).cells, g.cells);
        const auto header = carmen::read_first_gridmap_header(path);
        ASSERT_TRUE(header);
        EXPECT_EQ(header->size_x, 3);
        EXPECT_EQ(carmen::list_map_chunks(path).size(), 1u);
        EXPECT_FALSE(carmen::read_first_chunk(path, carmen::kOfflimitsChunk));
      }
    }
  }
}

// Memory stays bounded by what the file holds: a gridmap cut short is read
// only when at least half of its cell bytes (or all but 1 MiB) are there. A
// header cut short, or one whose size does not match its cells, is damage.
TEST(MapFileShortGridmap, TooLittleOfItIsRefused) {
  TempDir dir;
  const int32_t side = 1024;  // 4 MiB of cells
  const std::string head = std::string(1, '\x01') + i32(10 + 12 + 4 * side * side) + "GRIDMAP   " + i32(side) +
                           i32(side) + f32(0.1f);
  const size_t half = size_t(2) * side * side;
  std::string halves;  // the first half of the cells, each 0.5
  for (size_t i = 0; i < half / 4; ++i) halves += f32(0.5f);
  for (const char *ext : {".map", ".map.gz"}) {
    const std::string path = dir.file(std::string("half") + ext);
    write_plain_or_gzip(path, kId + head + halves);
    std::vector<std::string> warnings;
    const MapFile m = read_warned(path, &warnings);
    ASSERT_TRUE(m.gridmap);
    EXPECT_EQ(m.gridmap->at(511, 1023), 0.5f);
    EXPECT_EQ(m.gridmap->at(512, 0), 0.0f);  // missing: a zero, as in CARMEN's calloc()ed grid
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("is 2097152 bytes short"), std::string::npos) << warnings[0];

    write_plain_or_gzip(path, kId + head + std::string(half - 4, '\0'));
    g_largest_alloc = 0;
    expect_rejected(path, {"GRIDMAP chunk at byte 17", "claims 4194326 bytes", "fewer than half of its cells"});
    if (std::string(ext) == ".map") {
      EXPECT_LT(g_largest_alloc.load(), half);  // refused before the cells were allocated
      expect_rejected(path, {"but only 2097170 remain in the file: it is truncated or damaged"});
    }
  }
  write_bytes(dir.file("head.map"), kId + head.substr(0, head.size() - 2));
  expect_rejected(dir.file("head.map"), {"GRIDMAP", "cut short", "map size"});
}

// ---------------------------------------------------------------------------
// OFFLIMITS chunks as CARMEN 0.7.4's writers write them
// ---------------------------------------------------------------------------
// A list whose second line comes after the first `lines` (2) items, so that
// CARMEN's line loop leaves it out: the chunk holds 1 of its 2 counted lines
// and ends 16 bytes before its size says.
const std::vector<CarmenOffItem> kCarmenList = {
    {0, 1, 2, 0, 0}, {1, 0, 0, 5, 5}, {2, 1, 1, 2, 2}, {1, 3, 4, 7, 8}, {0, -3, 9, 0, 0}};

void expect_carmen_list(const carmen::OffLimits &o) {
  ASSERT_EQ(o.points.size(), 2u);
  EXPECT_EQ(o.points[1].x, -3);
  EXPECT_EQ(o.points[1].y, 9);
  ASSERT_EQ(o.lines.size(), 1u);  // the one CARMEN wrote
  EXPECT_EQ(o.lines[0].x2, 5);
  ASSERT_EQ(o.rects.size(), 1u);
  EXPECT_EQ(o.rects[0].x1, 1);
  EXPECT_EQ(o.rects[0].y2, 2);
}

TEST(MapFileCarmenOfflimits, TheWritersLayoutsAreRead) {
  TempDir dir;
  const std::string grid = chunk(1, "GRIDMAP", i32(1) + i32(1) + f32(1) + f32(0.5f));
  const std::string scans = chunk(16, "LASERSCANS", i32(1) + f32(1) + f32(2) + f32(3) + i32(1) + f32(4));
  const std::string plain = carmen_offlimits_chunk(kCarmenList);
  const std::string named = carmen_offlimits_chunk(kCarmenList, "zone", true);
  ASSERT_EQ(read_i32(plain, 1), 10 + 12 + 2 * 8 + 3 * 16);  // the size counts the line left out
  ASSERT_EQ(plain.size(), 5 + 10 + 12 + 2 * 8 + 2 * 16u);
  ASSERT_EQ(read_i32(named, 1), 22);
  const size_t off_at = kId.size() + grid.size();
  // Unnamed last (its size runs past the end of the file), unnamed then
  // another chunk (its size runs into it), named (size 22) in both places.
  const std::string files[] = {kId + grid + plain, kId + grid + plain + scans, kId + grid + named,
                               kId + grid + named + scans};
  for (const std::string &bytes : files) {
    const bool is_named = bytes.find("zone") != std::string::npos;
    const bool has_scans = bytes.size() > off_at + (is_named ? named : plain).size();
    for (const char *ext : {".map", ".map.gz"}) {
      const std::string path = dir.file(std::string("carmen") + ext);
      write_plain_or_gzip(path, bytes);
      std::vector<std::string> warnings;
      const MapFile m = read_warned(path, &warnings);
      if (is_named) {
        ASSERT_EQ(m.named.size(), 1u);
        EXPECT_EQ(m.named[0].name, "zone");
        expect_carmen_list(std::get<carmen::OffLimits>(m.named[0].payload));
      } else {
        ASSERT_TRUE(m.offlimits);
        expect_carmen_list(*m.offlimits);
      }
      ASSERT_EQ(m.laserscans.has_value(), has_scans) << path;
      if (has_scans) {
        EXPECT_EQ((*m.laserscans)[0].ranges, std::vector<float>{4.0f});
      }
      ASSERT_EQ(warnings.size(), 1u);
      EXPECT_NE(warnings[0].find("warning: the OFFLIMITS chunk at byte " + std::to_string(off_at)),
                std::string::npos)
          << warnings[0];
      EXPECT_NE(warnings[0].find("1 of its 2 lines were counted but never written"), std::string::npos)
          << warnings[0];
      EXPECT_EQ(m.unknown_chunks, 0);

      // The header scans find the chunk after it where it is.
      const auto chunks = carmen::list_map_chunks(path);
      ASSERT_EQ(chunks.size(), has_scans ? 3u : 2u);
      if (has_scans) {
        EXPECT_EQ(chunks[2].offset, int64_t(off_at + (is_named ? named : plain).size()));
      }
      EXPECT_EQ(carmen::read_first_chunk(path, carmen::kLaserscansChunk).has_value(), has_scans);
      const std::string zone = "zone";
      const auto found = carmen::read_first_chunk(path, carmen::kOfflimitsChunk, is_named ? &zone : nullptr);
      ASSERT_TRUE(found);
      expect_carmen_list(std::get<carmen::OffLimits>(found->payload));
      // Indexed (mapconvert --info) and read when asked.
      carmen::MapReadOptions index;
      index.named_chunks = carmen::NamedChunkReading::Index;
      const MapFile listed = read_warned(path, &warnings, index);
      EXPECT_EQ(listed.laserscans.has_value(), has_scans);
      if (is_named) {
        expect_carmen_list(std::get<carmen::OffLimits>(carmen::read_named_chunk(path, chunks[1]).payload));
      }

      // Written back in the layout the size gives: read without a warning.
      const std::string copy = dir.file("copy.map");
      carmen::write_map_file(copy, m);
      warnings.clear();
      const MapFile again = read_warned(copy, &warnings);
      EXPECT_TRUE(warnings.empty());
      expect_carmen_list(is_named ? std::get<carmen::OffLimits>(again.named.at(0).payload) : *again.offlimits);
    }
  }
}

// The named writer's layout when no line is left out (lines first in the
// list), and a chunk in neither layout, which is still damage.
TEST(MapFileCarmenOfflimits, NamedSizeIsNotTrustedButDamageIsStillAnError) {
  TempDir dir;
  const std::string path = dir.file("named.map");
  write_bytes(path, kId + carmen_offlimits_chunk({{1, 1, 2, 3, 4}, {0, 5, 6, 0, 0}}, "a long zone name", true) +
                        chunk(64, "OFFSET", f64(1) + f64(2) + f64(3)));
  std::vector<std::string> warnings;
  const MapFile m = read_warned(path, &warnings);
  ASSERT_EQ(m.named.size(), 1u);
  const auto &o = std::get<carmen::OffLimits>(m.named[0].payload);
  EXPECT_EQ(o.lines.size(), 1u);
  EXPECT_EQ(o.points.size(), 1u);
  ASSERT_TRUE(m.offset);
  EXPECT_EQ(m.offset->theta, 3.0);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("(named \"a long zone name\") is laid out as CARMEN 0.7.4's writer lays it out, "
                             "not as its size field (22) says; it ends at byte"),
            std::string::npos)
      << warnings[0];
  // Counts that fit neither layout.
  const std::string offset = chunk(64, "OFFSET", f64(1) + f64(2) + f64(3));
  write_bytes(path, kId + chunk(2, "OFFLIMITS", i32(0) + i32(3) + i32(0)) + offset);
  expect_rejected(path, {"OFFLIMITS chunk at byte 17", "claims 3 lines"});
  write_bytes(path, kId + chunk(2, "OFFLIMITS", i32(0) + i32(3) + i32(0)));
  expect_rejected(path, {"OFFLIMITS chunk at byte 17", "claims 3 lines"});
}

// ---------------------------------------------------------------------------
// Round trips
// ---------------------------------------------------------------------------
class MapFileRoundTrip : public ::testing::TestWithParam<const char *> {};

TEST_P(MapFileRoundTrip, EveryChunkType) {
  TempDir dir;
  const std::string path = dir.file(std::string("all") + GetParam());
  const MapFile m = sample_map();
  carmen::write_map_file(path, m);
  const MapFile back = carmen::read_map_file(path);
  expect_same_map(m, back);
  EXPECT_EQ(back.unknown_chunks, 0);
  // 6 unnamed chunks + 6 named ones, in the documented order.
  ASSERT_EQ(back.chunks.size(), 12u);
  const int expected_types[] = {32, 1, 4, 2, 16, 64, 0x81, 0xC0, 0x84, 0x82, 0x90, 0xA0};
  for (size_t i = 0; i < 12; ++i) EXPECT_EQ(back.chunks[i].type, expected_types[i]) << i;
  EXPECT_EQ(back.chunks[6].name, "coarse");
  EXPECT_EQ(std::get<carmen::CreatorInfo>(back.named[5].payload).time_bytes, 4);
  const bool gz = std::string(GetParam()).find(".gz") != std::string::npos;
  EXPECT_EQ(read_bytes(path).substr(0, 2) == std::string("\x1f\x8b", 2), gz);
  EXPECT_EQ(dir.entries().size(), 1u);  // no temporary file left
}

TEST_P(MapFileRoundTrip, MinimalMaps) {
  TempDir dir;
  const std::string path = dir.file(std::string("min") + GetParam());
  MapFile empty;  // id only
  carmen::write_map_file(path, empty);
  const MapFile back = carmen::read_map_file(path);
  EXPECT_FALSE(back.gridmap);
  EXPECT_FALSE(back.creator);
  EXPECT_TRUE(back.chunks.empty());

  MapFile empties;  // present but empty lists
  empties.places = carmen::PlaceList{};
  empties.offlimits = carmen::OffLimits{};
  empties.laserscans = carmen::LaserScanList{};
  carmen::write_map_file(path, empties);
  expect_same_map(empties, carmen::read_map_file(path));
}

INSTANTIATE_TEST_SUITE_P(PlainAndGzip, MapFileRoundTrip, ::testing::Values(".map", ".map.gz"),
                         [](const auto &info) {
                           return std::string(info.param).size() > 4 ? "gzip" : "plain";
                         });

TEST(MapFile, CreatorTimeWidthFollowsTheChunkSize) {
  TempDir dir;
  for (int width : {4, 8}) {
    MapFile m;
    carmen::CreatorInfo c;
    c.user = "u";
    c.time = -5;  // sign must survive either width
    c.time_bytes = width;
    m.creator = c;
    const std::string path = dir.file("c" + std::to_string(width) + ".map");
    carmen::write_map_file(path, m);
    const std::string raw = read_bytes(path);
    // id, then type 32, size = 10 (description) + 10 + width + 80 + 80.
    ASSERT_EQ(raw.size(), 17u + 5u + 180u + size_t(width));
    EXPECT_EQ(uint8_t(raw[17]), 32);
    EXPECT_EQ(read_i32(raw, 18), 180 + width);
    EXPECT_EQ(raw.substr(22, 10), "CREATOR   ");
    EXPECT_EQ(raw.substr(32, 10), field("u", 10));
    const MapFile back = carmen::read_map_file(path);
    ASSERT_TRUE(back.creator);
    EXPECT_EQ(back.creator->time_bytes, width);
    EXPECT_EQ(back.creator->time, -5);
  }
  // A hand-made 64-bit creator with a time past 2038.
  const std::string payload =
      field("alice", 10) + i32(0x12345678) + i32(0x1) + field("o", 80) + field("d", 80);
  const std::string path = dir.file("hand.map");
  write_bytes(path, kId + chunk(32, "CREATOR", payload));
  const MapFile m = carmen::read_map_file(path);
  EXPECT_EQ(m.creator->time, 0x112345678LL);
  EXPECT_EQ(m.creator->user, "alice");
  // Any other width is damage.
  write_bytes(path, kId + chunk(32, "CREATOR", payload + "xx"));
  expect_rejected(path, {"CREATOR", "174", "178"});
}

TEST(MapFile, HandMadeFileDecodes) {
  // Every payload laid out by hand, as the format notes describe it.
  TempDir dir;
  const std::string grid = i32(2) + i32(3) + f32(0.5f) + f32(-1) + f32(0.25f) + f32(0.5f) + f32(0.75f) +
                           f32(1) + f32(0);  // x-major: (0,0) (0,1) (0,2) (1,0) (1,1) (1,2)
  const std::string places = i32(2) + i32(0) + field("a", 20, '\0') + f32(1) + f32(2) + i32(2) +
                             field("b", 20, '\0') + f32(1) + f32(2) + f32(3) + f32(4) + f32(5) + f32(6);
  const std::string offl = i32(1) + i32(7) + i32(8) + i32(1) + i32(1) + i32(2) + i32(3) + i32(4) + i32(0);
  const std::string scans = i32(1) + f32(1) + f32(2) + f32(3) + i32(2) + f32(4) + f32(5);
  const std::string offset = f64(1.5) + f64(-2.5) + f64(0.25);
  const std::string file = "# hello\n#\n" + kId + chunk(1, "GRIDMAP", grid) + chunk(4, "PLACES", places) +
                           chunk(2, "OFFLIMITS", offl) + chunk(16, "LASERSCANS", scans) +
                           chunk(64, "OFFSET", offset) + chunk(99, "MYSTERY", "abc") +
                           chunk(1, "GRIDMAP", i32(1) + i32(1) + f32(1) + f32(0.5f), "tiny", true);
  const std::string path = dir.file("hand.map");
  write_bytes(path, file);
  const MapFile m = carmen::read_map_file(path);
  EXPECT_EQ(m.comments, (std::vector<std::string>{" hello", ""}));
  ASSERT_TRUE(m.gridmap);
  EXPECT_EQ(m.gridmap->size_x, 2);
  EXPECT_EQ(m.gridmap->size_y, 3);
  EXPECT_EQ(m.gridmap->resolution, 0.5);
  EXPECT_EQ(m.gridmap->at(0, 0), -1.0f);
  EXPECT_EQ(m.gridmap->at(0, 2), 0.5f);
  EXPECT_EQ(m.gridmap->at(1, 0), 0.75f);
  EXPECT_EQ(m.gridmap->at(1, 2), 0.0f);
  ASSERT_TRUE(m.places);
  ASSERT_EQ(m.places->size(), 2u);
  EXPECT_EQ((*m.places)[0].name, "a");
  EXPECT_EQ((*m.places)[0].y, 2.0);
  EXPECT_EQ((*m.places)[1].type, 2);  // CARMEN_LOCALIZATION_INIT_TYPE
  EXPECT_EQ((*m.places)[1].theta_std, 6.0);
  ASSERT_TRUE(m.offlimits);
  ASSERT_EQ(m.offlimits->points.size(), 1u);
  EXPECT_EQ(m.offlimits->points[0].y, 8);
  ASSERT_EQ(m.offlimits->lines.size(), 1u);
  EXPECT_EQ(m.offlimits->lines[0].x2, 3);
  EXPECT_TRUE(m.offlimits->rects.empty());
  ASSERT_TRUE(m.laserscans);
  EXPECT_EQ((*m.laserscans)[0].theta, 3.0);
  EXPECT_EQ((*m.laserscans)[0].ranges, (std::vector<float>{4, 5}));
  ASSERT_TRUE(m.offset);
  EXPECT_EQ(m.offset->y, -2.5);
  EXPECT_EQ(m.unknown_chunks, 1);
  ASSERT_EQ(m.named.size(), 1u);
  EXPECT_EQ(m.named[0].name, "tiny");
  EXPECT_EQ(std::get<carmen::GridMap>(m.named[0].payload).cells, std::vector<float>{0.5f});
  EXPECT_EQ(m.chunks[5].type, 99);
  EXPECT_FALSE(m.chunks[5].used);

  // The header scan sees the same chunks.
  const auto chunks = carmen::list_map_chunks(path);
  ASSERT_EQ(chunks.size(), 7u);
  EXPECT_EQ(chunks[6].type, 0x81);
  EXPECT_EQ(chunks[6].name, "tiny");
  EXPECT_TRUE(carmen::is_map_file(path));
}

TEST(MapFile, WrittenBytesFollowTheLayout) {
  TempDir dir;
  MapFile m;
  carmen::GridMap g = carmen::GridMap::filled(2, 1, 0.5, 0.25f);
  g.at(1, 0) = -1.0f;
  m.gridmap = g;
  m.named.push_back({"ab", carmen::GlobalOffset{1, 2, 3}});
  const std::string path = dir.file("bytes.map");
  carmen::write_map_file(path, m);
  const std::string expected = kId + std::string("\x01", 1) + i32(10 + 12 + 8) + "GRIDMAP   " + i32(2) +
                               i32(1) + f32(0.5f) + f32(0.25f) + f32(-1.0f) + std::string("\xC0", 1) +
                               i32(10 + 3 + 24) + "OFFSET    " + std::string("ab\0", 3) + f64(1) + f64(2) +
                               f64(3);
  EXPECT_EQ(read_bytes(path), expected);
}

TEST(MapFile, OldStyleCreatorAndDuplicates) {
  TempDir dir;
  const std::string creator = field("bob", 10) + i32(100) + field("old", 80) + field("style", 80);
  const std::string g1 = i32(1) + i32(1) + f32(1) + f32(0.25f);
  const std::string g2 = i32(1) + i32(1) + f32(1) + f32(0.75f);
  const std::string path = dir.file("old.map");
  write_bytes(path, kId + chunk(0, "CREATOR", creator) + chunk(1, "GRIDMAP", g1) + chunk(1, "GRIDMAP", g2));
  const MapFile m = carmen::read_map_file(path);
  ASSERT_TRUE(m.creator);
  EXPECT_TRUE(m.old_style_creator);
  EXPECT_EQ(m.creator->user, "bob");
  EXPECT_EQ(m.gridmap->cells, std::vector<float>{0.25f});  // the first one wins, as in CARMEN
  EXPECT_EQ(m.unknown_chunks, 1);
  // A code-32 creator takes precedence over a code-0 one.
  write_bytes(path, kId + chunk(0, "CREATOR", creator) +
                        chunk(32, "CREATOR", field("new", 10) + i32(1) + field("", 80) + field("", 80)));
  const MapFile n = carmen::read_map_file(path);
  EXPECT_FALSE(n.old_style_creator);
  EXPECT_EQ(n.creator->user, "new");
}

TEST(MapFile, CommentsAreKeptReadableByCarmen) {
  TempDir dir;
  MapFile m;
  m.comments = {std::string(150, 'x'), "two\nlines", ""};
  const std::string path = dir.file("c.map");
  carmen::write_map_file(path, m);
  const std::string raw = read_bytes(path);
  // '#' + 97 characters + '\n' = 99 bytes: one fgets(buf, 100) call reads it.
  EXPECT_EQ(raw, "#" + std::string(97, 'x') + "\n#two lines\n#\n" + kId);
  const MapFile back = carmen::read_map_file(path);
  EXPECT_EQ(back.comments, (std::vector<std::string>{std::string(97, 'x'), "two lines", ""}));
}

// CARMEN 0.7.4's comment block (carmen_map_write_comment_chunk), line by
// line. This test used to look for "0.05": CARMEN prints the resolution with
// "%.1f", and the block is now CARMEN's, so 0.05 reads "0.1" there (the
// gridmap chunk holds the exact value).
TEST(MapFile, StandardCommentsAreCarmens) {
  const time_t t = 1700000000;
  const auto lines = carmen::standard_map_comments(300, 200, 0.05, "fr079.log", "test run", "me", t);
  std::string date = std::asctime(std::localtime(&t));
  date.pop_back();  // asctime's newline ends the line
  const std::string rule(52, '#');
  EXPECT_EQ(lines, (std::vector<std::string>{rule, "", " Carnegie Mellon Robot Toolkit (CARMEN) map file", "",
                                             " Map author    : me", " Creation date : " + date,
                                             " Map size      : 300 x 200", " Resolution    : 0.1",
                                             " Origin        : fr079.log", " Description   : test run#", rule}));
  // Written out, they are CARMEN's bytes: 53 '#', and the Description line
  // running into the '#' CARMEN writes next.
  const std::string bytes = carmen::encode_comment_lines(lines);
  EXPECT_EQ(bytes.substr(0, 54), std::string(53, '#') + "\n");
  EXPECT_NE(bytes.find("# Description   : test run#\n" + std::string(53, '#') + "\n"), std::string::npos);
  // A description with its own newline: CARMEN's "#" then has a line of its own.
  const auto own = carmen::standard_map_comments(1, 1, 1, "o", "d\n", "me", t);
  EXPECT_EQ(own[9], " Description   : d");
  EXPECT_EQ(own[10], "");
  EXPECT_EQ(own[11], rule);
}

// ---------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------
// ---------------------------------------------------------------------------
// One chunk, found as CARMEN finds it
// ---------------------------------------------------------------------------
TEST(MapFileFirstChunk, ScanStopsAtTheChunkAskedFor) {
  TempDir dir;
  const std::string grid = i32(2) + i32(1) + f32(0.5f) + f32(0.25f) + f32(-1.0f);
  const std::string places = i32(1) + i32(0) + field("p", 20) + f32(1) + f32(2);
  // A named gridmap first, then an unnamed one, then a chunk whose header
  // claims far more bytes than the file holds.
  const std::string head = kId + chunk(1, "GRIDMAP", grid, "named", true) + chunk(1, "GRIDMAP", grid) +
                           chunk(4, "PLACES", places);
  const size_t damaged_at = head.size();
  const std::string bytes = head + std::string(1, '\x66') + i32(0x50000000) + "JUNK      " + "xyz";
  for (const std::string name : {"f.map", "f.map.gz"}) {
    const std::string path = dir.file(name);
    if (name.size() > 6) {
      gzip_to_file(path, bytes);
    } else {
      write_bytes(path, bytes);
    }
    const auto g = carmen::read_first_chunk(path, carmen::kGridmapChunk);
    ASSERT_TRUE(g);
    EXPECT_EQ(g->info.offset, 17);
    EXPECT_TRUE(g->info.named());
    EXPECT_EQ(g->info.name, "named");
    EXPECT_EQ(std::get<carmen::GridMap>(g->payload).cells, (std::vector<float>{0.25f, -1.0f}));
    const std::string unnamed_name = "named";
    const auto n = carmen::find_first_chunk(path, carmen::kGridmapChunk | carmen::kNamedChunkFlag, &unnamed_name);
    ASSERT_TRUE(n);
    EXPECT_EQ(n->offset, 17);
    const auto h = carmen::read_first_gridmap_header(path);
    ASSERT_TRUE(h);
    EXPECT_EQ(h->size_x, 2);
    EXPECT_EQ(h->size_y, 1);
    EXPECT_EQ(h->resolution, 0.5);
    const auto p = carmen::read_first_chunk(path, carmen::kPlacesChunk);
    ASSERT_TRUE(p);
    EXPECT_EQ(std::get<carmen::PlaceList>(p->payload).size(), 1u);
    // What lies after the damage cannot be found: the damage is reported
    // with its offset.
    try {
      carmen::find_first_chunk(path, carmen::kCreatorChunk);
      ADD_FAILURE() << "no error for the damaged chunk";
    } catch (const FileError &e) {
      EXPECT_NE(std::string(e.what()).find("at byte " + std::to_string(damaged_at)), std::string::npos)
          << e.what();
    }
    const std::string other = "other";
    EXPECT_THROW(carmen::read_first_chunk(path, carmen::kGridmapChunk, &other), FileError);
    EXPECT_THROW(carmen::read_first_chunk(path, carmen::kHmapChunk), std::invalid_argument);
  }
}

TEST(MapFileFirstChunk, GridmapHeaderNeedsNoCells) {
  TempDir dir;
  // A 1000 x 1000 gridmap whose cells are missing, in a gzip file (whose
  // size is not known before reading): the header is read, the cells are
  // refused when asked for, and nothing near 4 MB is allocated up front.
  const std::string body = i32(1000) + i32(1000) + f32(0.1f);
  const std::string bytes =
      kId + std::string(1, '\x01') + i32(10 + 12 + 4 * 1000000) + "GRIDMAP   " + body + f32(0.5f);
  const std::string path = dir.file("short.map.gz");
  gzip_to_file(path, bytes);
  const auto h = carmen::read_first_gridmap_header(path);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->size_x, 1000);
  EXPECT_EQ(h->info.size, 10 + 12 + 4 * 1000000);
  EXPECT_THROW(carmen::read_first_chunk(path, carmen::kGridmapChunk), FileError);
  // A header whose size does not match its cells is damage, even here.
  write_bytes(dir.file("bad.map"), kId + chunk(1, "GRIDMAP", i32(3) + i32(3) + f32(0.1f) + f32(0)));
  EXPECT_THROW(carmen::read_first_gridmap_header(dir.file("bad.map")), FileError);
}

TEST(MapFileBad, MissingEmptyAndForeignFiles) {
  TempDir dir;
  expect_rejected(dir.file("nope.map"), {"cannot open"});
  expect_rejected(dir.path(), {"directory"});
  write_bytes(dir.file("empty.map"), "");
  expect_rejected(dir.file("empty.map"), {"empty"});
  write_bytes(dir.file("text.map"), "hello world, this is not a map\n");
  expect_rejected(dir.file("text.map"), {"not a CARMEN map"});
  write_bytes(dir.file("comments.map"), "# only\n# comments\n");
  expect_rejected(dir.file("comments.map"), {"no CARMENMAPFILEv020 id"});
  write_bytes(dir.file("v019.map"), "CARMENMAPFILEv019");
  expect_rejected(dir.file("v019.map"), {"version", "v019"});
  write_bytes(dir.file("shortid.map"), "CARMENMAPFI");
  expect_rejected(dir.file("shortid.map"), {"not a CARMEN map"});
  write_bytes(dir.file("shortid2.map"), "CARMENMAPFILEv0");
  expect_rejected(dir.file("shortid2.map"), {"cut short"});
  // gzip data under a plain name.
  gzip_to_file(dir.file("zipped.map"), kId);
  expect_rejected(dir.file("zipped.map"), {"gzip", ".gz"});
  EXPECT_FALSE(carmen::is_map_file(dir.file("zipped.map")));
  EXPECT_FALSE(carmen::is_map_file(dir.file("nope.map")));
  write_bytes(dir.file("long.map"), "#" + std::string(5000, 'c') + "\n" + kId);
  expect_rejected(dir.file("long.map"), {"comment line longer"});
}

TEST(MapFileBad, InconsistentChunks) {
  TempDir dir;
  const std::string p = dir.file("bad.map");
  auto check = [&](const std::string &body, const std::vector<std::string> &parts) {
    write_bytes(p, kId + body);
    expect_rejected(p, parts);
  };
  check(std::string("\x01", 1) + i32(5) + "GRIDMAP   ", {"size 5", "less than"});
  check(std::string("\x01", 1) + i32(-100) + "GRIDMAP   ", {"size -100"});
  check(std::string("\x01\x02", 2), {"cut short", "header"});
  check(chunk(1, "GRIDMAP", i32(2) + i32(2) + f32(0.1f) + f32(0)), {"GRIDMAP", "2 x 2", "need a size of 38"});
  check(chunk(1, "GRIDMAP", i32(-2) + i32(2) + f32(0.1f)), {"invalid map size -2 x 2"});
  check(chunk(1, "GRIDMAP", i32(1) + i32(1) + f32(0) + f32(0)), {"invalid resolution"});
  check(chunk(1, "GRIDMAP", i32(1) + i32(1) + f32(std::nanf("")) + f32(0)), {"invalid resolution"});
  check(chunk(1, "GRIDMAP", i32(1) + i32(1)), {"too few"});
  check(chunk(1, "GRIDMAP", i32(1) + i32(1) + f32(1) + f32(1.5f)), {"invalid cell values", "(0, 0) = 1.5"});
  check(chunk(1, "GRIDMAP", i32(1) + i32(2) + f32(1) + f32(0) + f32(std::nanf(""))),
        {"invalid cell values", "1 of 2", "(0, 1)"});
  check(chunk(4, "PLACES", i32(1) + i32(9) + field("p", 20, '\0') + f32(0) + f32(0)),
        {"PLACES", "unknown type 9"});
  check(chunk(4, "PLACES", i32(1) + i32(0) + field("p", 20, '\0') + f32(0) + f32(0) + "zz"),
        {"PLACES", "2 unexpected bytes"});
  check(chunk(4, "PLACES", i32(-1)), {"negative"});
  check(chunk(4, "PLACES", i32(2) + i32(0) + field("p", 20, '\0') + f32(0) + f32(0)), {"claims 2 places"});
  check(chunk(2, "OFFLIMITS", i32(1) + i32(1) + i32(1)), {"OFFLIMITS", "ends inside"});
  check(chunk(16, "LASERSCANS", i32(1) + f32(0) + f32(0) + f32(0) + i32(1000)), {"claims 1000 readings"});
  check(chunk(64, "OFFSET", f64(1) + f64(2)), {"OFFSET", "24"});
  check(chunk(32, "CREATOR", std::string(20, ' ')), {"CREATOR"});
  check(std::string("\x81", 1) + i32(14) + "GRIDMAP   " + "abcd", {"name", "past the end"});
  check(chunk(1, "GRIDMAP", i32(1) + i32(1) + f32(1) + f32(0)) + "\x05\x00", {"cut short"});
}

TEST(MapFileBad, TruncatedAnywhere) {
  // Every prefix of a valid file either fails with a FileError naming the
  // file or — cut exactly between chunks — reads as fewer chunks, or — cut
  // inside a gridmap's cells — reads with the rest of them unknown and a
  // warning, as CARMEN reads a map cut short.
  TempDir dir;
  const std::string full_path = dir.file("full.map");
  carmen::write_map_file(full_path, sample_map());
  const std::string full = read_bytes(full_path);
  const auto boundaries = carmen::list_map_chunks(full_path);
  std::vector<size_t> cuts_ok{full.find(kId) + kId.size()};
  for (const auto &c : boundaries) cuts_ok.push_back(size_t(c.offset) + 5 + size_t(c.size));
  std::vector<std::pair<size_t, size_t>> cells;  // [first, end) of each gridmap's cell bytes
  for (const auto &c : boundaries) {
    if (c.base_type() != carmen::kGridmapChunk) continue;
    const size_t first = size_t(c.offset) + 5 + 10 + (c.named() ? c.name.size() + 1 : 0) + 12;
    cells.emplace_back(first, size_t(c.offset) + 5 + size_t(c.size));
  }
  ASSERT_EQ(cells.size(), 2u);
  for (const char *ext : {".map", ".map.gz"}) {
    const std::string path = dir.file(std::string("cut") + ext);
    for (size_t n = 0; n < full.size(); ++n) {
      if (std::string(ext) == ".map") {
        write_bytes(path, full.substr(0, n));
      } else {
        gzip_to_file(path, full.substr(0, n));
      }
      const bool boundary = std::find(cuts_ok.begin(), cuts_ok.end(), n) != cuts_ok.end();
      const bool in_cells =
          std::any_of(cells.begin(), cells.end(), [n](const auto &r) { return n >= r.first && n < r.second; });
      std::vector<std::string> warnings;
      carmen::MapReadOptions opts;
      opts.on_warning = [&](const std::string &w) { warnings.push_back(w); };
      try {
        const MapFile m = carmen::read_map_file(path, opts);
        EXPECT_TRUE(boundary || in_cells) << "prefix of " << n << " bytes accepted";
        EXPECT_LT(m.chunks.size(), boundaries.size());
        ASSERT_EQ(warnings.size(), in_cells ? 1u : 0u) << n;
        if (in_cells) {
          EXPECT_EQ(warnings[0].rfind(path + ": warning: the GRIDMAP chunk at byte ", 0), 0u) << warnings[0];
        }
      } catch (const FileError &e) {
        EXPECT_FALSE(boundary || in_cells) << n << ": " << e.what();
        EXPECT_EQ(e.file(), path);
      }
    }
  }
  // And a gzip stream cut short (not the data inside: the stream itself).
  const std::string gz_path = dir.file("full.map.gz");
  carmen::write_map_file(gz_path, sample_map());
  const std::string gz = read_bytes(gz_path);
  write_bytes(dir.file("cutgz.map.gz"), gz.substr(0, gz.size() / 2));
  expect_rejected(dir.file("cutgz.map.gz"), {"gzip"});
}

TEST(MapFileBad, HugeClaimsAreNotAllocated) {
  TempDir dir;
  // A GRIDMAP whose size field and cell count agree (16000 x 8000 cells,
  // 512,000,000 bytes) in a file of a few bytes; an unknown chunk, a place
  // list and a scan claiming near 2 GiB.
  const int32_t sx = 16000, sy = 8000;
  const std::string head = std::string("\x01", 1) + i32(10 + 12 + 4 * sx * sy) + "GRIDMAP   " + i32(sx) +
                           i32(sy) + f32(0.1f) + std::string(64, '\0');
  const std::string unknown = std::string("\x33", 1) + i32(0x7ffffff0) + "JUNK      " + "x";
  const std::string places = chunk(4, "PLACES", i32(0x40000000));
  const std::string scans = chunk(16, "LASERSCANS", i32(1) + f32(0) + f32(0) + f32(0) + i32(0x7fffffff));
  for (const std::string &body : {head, unknown, places, scans}) {
    for (const char *ext : {".map", ".map.gz"}) {
      const std::string path = dir.file(std::string("huge") + ext);
      if (std::string(ext) == ".map") {
        write_bytes(path, kId + body);
      } else {
        gzip_to_file(path, kId + body);
      }
      g_largest_alloc = 0;
      EXPECT_THROW(carmen::read_map_file(path), FileError) << ext;
      EXPECT_LT(g_largest_alloc.load(), kAllocLimit) << ext << ": a claimed size was allocated";
    }
  }
  // The plain file is refused by its size alone, before reading the cells.
  write_bytes(dir.file("huge.map"), kId + head);
  expect_rejected(dir.file("huge.map"), {"claims 512000022 bytes but only", "remain"});
}

TEST(MapFileBad, RandomDamageNeverCrashes) {
  TempDir dir;
  const std::string full_path = dir.file("full.map");
  carmen::write_map_file(full_path, sample_map());
  const std::string full = read_bytes(full_path);
  std::mt19937 rng(vasco::testing_support::test_seed(12345));
  const std::string path = dir.file("fuzz.map");
  int rejected = 0;
  for (int round = 0; round < 3000; ++round) {
    std::string s = full;
    const int flips = 1 + int(rng() % 4);
    for (int k = 0; k < flips; ++k) {
      const size_t at = rng() % s.size();
      s[at] = static_cast<char>(rng() % 3 == 0 ? 0xff : (rng() & 0xff));
    }
    write_bytes(path, s);
    g_largest_alloc = 0;
    try {
      carmen::read_map_file(path);
    } catch (const FileError &) {
      ++rejected;
    } catch (const std::exception &e) {
      ADD_FAILURE() << "round " << round << ": " << e.what();
    }
    EXPECT_LT(g_largest_alloc.load(), kAllocLimit) << "round " << round;
  }
  EXPECT_GT(rejected, 100);  // damage is noticed, not just survived
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------
TEST(MapFileWrite, InvalidMapsThrowAndLeaveNothing) {
  TempDir dir;
  MapFile m;
  m.gridmap = carmen::GridMap{};
  m.gridmap->size_x = 2;
  m.gridmap->size_y = 2;
  m.gridmap->resolution = 0.1;
  m.gridmap->cells = {0, 0, 0};  // one short
  EXPECT_THROW(carmen::write_map_file(dir.file("a.map"), m), std::invalid_argument);
  MapFile n;
  n.named.push_back({"", carmen::GlobalOffset{}});
  EXPECT_THROW(carmen::write_map_file(dir.file("b.map"), n), std::invalid_argument);
  MapFile p;
  p.places = carmen::PlaceList{{7, "bad", 0, 0, 0, 0, 0, 0}};
  EXPECT_THROW(carmen::write_map_file(dir.file("c.map"), p), std::invalid_argument);
  MapFile c;
  c.creator = carmen::CreatorInfo{};
  c.creator->time_bytes = 2;
  EXPECT_THROW(carmen::write_map_file(dir.file("d.map"), c), std::invalid_argument);
  EXPECT_TRUE(dir.entries().empty());
}

TEST(MapFileWrite, FailureKeepsTheOldFile) {
  TempDir dir;
  const std::string path = dir.file("keep.map");
  write_bytes(path, "old contents");
  MapFile bad;
  bad.gridmap = carmen::GridMap::filled(2, 2, 0.1);
  bad.gridmap->cells.pop_back();
  EXPECT_THROW(carmen::write_map_file(path, bad), std::invalid_argument);
  EXPECT_EQ(read_bytes(path), "old contents");
  try {
    carmen::write_map_file(dir.file("no/such/dir/x.map"), sample_map());
    ADD_FAILURE() << "wrote into a missing directory";
  } catch (const FileError &e) {
    EXPECT_NE(std::string(e.what()).find("no/such/dir/x.map"), std::string::npos) << e.what();
  }
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.map"});
}

TEST(MapFileCells, ValidValues) {
  // The rule, value by value: -1, [0,1] and [2,3] only.
  EXPECT_TRUE(carmen::valid_cell_value(-1.0f));
  EXPECT_TRUE(carmen::valid_cell_value(0.0f));
  EXPECT_TRUE(carmen::valid_cell_value(0.004f));
  EXPECT_TRUE(carmen::valid_cell_value(1.0f));
  EXPECT_TRUE(carmen::valid_cell_value(2.0f));
  EXPECT_TRUE(carmen::valid_cell_value(3.0f));
  EXPECT_FALSE(carmen::valid_cell_value(-0.5f));
  EXPECT_FALSE(carmen::valid_cell_value(-1.0001f));
  EXPECT_FALSE(carmen::valid_cell_value(1.5f));
  EXPECT_FALSE(carmen::valid_cell_value(3.5f));
  EXPECT_FALSE(carmen::valid_cell_value(2.5e38f));
  EXPECT_FALSE(carmen::valid_cell_value(std::numeric_limits<float>::infinity()));
  EXPECT_FALSE(carmen::valid_cell_value(std::nanf("")));
}

TEST(MapFileCells, AtIsBoundsChecked) {
  carmen::GridMap g = carmen::GridMap::filled(3, 2, 0.1, 0.5f);
  g.at(2, 1) = 0.25f;
  EXPECT_EQ(g.cells[2 * 2 + 1], 0.25f);  // x-major
  EXPECT_THROW(g.at(3, 0), std::out_of_range);
  EXPECT_THROW(g.at(0, -1), std::out_of_range);
}

}  // namespace

namespace {

// Named GRIDMAP chunks are all parsed and kept: a file of many of them (a
// few KB of .gz can claim gigabytes) is refused at MapReadOptions'
// max_kept_bytes instead of being allocated.
TEST(MapFileLimits, ChunkDataBeyondTheBudgetIsRefused) {
  maptest::TempDir dir;
  carmen::MapFile m;
  m.gridmap = carmen::GridMap::filled(300, 300, 0.1, 0.5f);  // 360 KB of cells
  for (int i = 0; i < 3; ++i) m.named.push_back({"copy" + std::to_string(i), *m.gridmap});
  const std::string path = dir.file("many.map.gz");
  carmen::write_map_file(path, m);
  EXPECT_EQ(carmen::MapReadOptions{}.max_kept_bytes, uint64_t(1) << 30);
  EXPECT_EQ(carmen::read_map_file(path).named.size(), 3u);  // well inside the default
  carmen::MapReadOptions small;
  small.max_kept_bytes = 1 << 20;
  try {
    carmen::read_map_file(path, small);
    ADD_FAILURE() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("max_kept_bytes"), std::string::npos) << e.what();
    EXPECT_EQ(e.code(), carmen::ErrorCode::TooLarge);
  }
}

// read_chunk_body (the C API's HMAP reader and carmen_map_name_chunk use
// it): a .gz chunk's size is not checked against the file, so one claiming
// more than max_kept_bytes is refused before it is read; a plain file's is
// checked against what the file holds.
TEST(MapFileLimits, ChunkBodiesBeyondTheBudgetAreRefusedBeforeTheyAreRead) {
  maptest::TempDir dir;
  const std::string bytes = maptest::kId + std::string(1, '\x66') + maptest::i32(0x7ffffff0) + "JUNK      " +
                            std::string(4000, 'a');
  carmen::ChunkInfo c;
  c.type = 0x66;
  c.offset = int64_t(maptest::kId.size());
  c.size = 0x7ffffff0;
  const std::string gz = dir.file("claims.map.gz");
  maptest::gzip_to_file(gz, bytes);
  try {
    carmen::read_chunk_body(gz, c);
    ADD_FAILURE() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_EQ(e.file(), gz);
    EXPECT_EQ(e.code(), carmen::ErrorCode::TooLarge) << e.what();
    EXPECT_NE(std::string(e.what()).find("claims 2147483632 bytes, more than the 1024 MiB"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("gunzip"), std::string::npos) << e.what();
  }
  const std::string plain = dir.file("claims.map");
  maptest::write_bytes(plain, bytes);
  try {
    carmen::read_chunk_body(plain, c);
    ADD_FAILURE() << "no error";
  } catch (const carmen::FileError &e) {
    EXPECT_NE(std::string(e.what()).find("only 4010 remain in the file"), std::string::npos) << e.what();
  }
  c.size = 4010;  // what is there reads
  EXPECT_EQ(carmen::read_chunk_body(plain, c), "JUNK      " + std::string(4000, 'a'));
  EXPECT_EQ(carmen::read_chunk_body(gz, c), "JUNK      " + std::string(4000, 'a'));
}

// CARMEN's C gridmap readers: a C caller cannot raise max_kept_bytes. A
// plain map's chunk sizes are checked against the file, so there is no
// limit (CARMEN reads maps above 16384 x 16384); a .gz keeps the limit, and
// the message says what to do. (A map over 1 GiB would make a slow test:
// the header of one is enough, the reader refusing before the cells.)
TEST(MapFileLimits, TheCGridmapReaderTellsToGunzipAGzipMapOverTheLimit) {
  maptest::TempDir dir;
  const int32_t side = 16500;  // 1089 MB of cells
  const std::string header = maptest::kId + std::string(1, '\x01') +
                             maptest::i32(int32_t(10 + 12 + int64_t(side) * side * 4)) + "GRIDMAP   " +
                             maptest::i32(side) + maptest::i32(side) + maptest::f32(0.05f) +
                             std::string(4096, '\0');
  const std::string gz = dir.file("large.map.gz");
  maptest::gzip_to_file(gz, header);
  carmen_map_t map;
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_gridmap_chunk(gz.c_str(), &map), -1);
  std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find(gz + ": its GRIDMAP chunk would take more than 1024 MiB"), std::string::npos) << err;
  EXPECT_NE(err.find("gunzip the map"), std::string::npos) << err;
  EXPECT_EQ(err.find("MapReadOptions"), std::string::npos) << err;  // nothing a C caller can set
  EXPECT_EQ(map.complete_map, nullptr);
  // The same header in a plain file: only the file's size limits it.
  const std::string plain = dir.file("large.map");
  maptest::write_bytes(plain, header);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_gridmap_chunk(plain.c_str(), &map), -1);
  err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("remain in the file: it is truncated or damaged"), std::string::npos) << err;
  EXPECT_EQ(err.find("max_kept_bytes"), std::string::npos) << err;
}

}  // namespace

namespace {

// PLACES type codes are CARMEN's map.h values (carmen-formats.md §3.3):
// 0 position (x y), 1 pose (x y theta), 2 localization init (6 floats).
// A chunk laid out by hand as CARMEN writes a pose reads as a pose, and ours
// puts the int 1 on disk for one.
TEST(MapFilePlaces, TypeCodesAreCarmens) {
  maptest::TempDir dir;
  carmen::MapFile m;
  m.gridmap = carmen::GridMap::filled(2, 2, 0.1, 0.5f);
  m.places = carmen::PlaceList{{carmen::kNamedPose, "desk", 1.0, 2.0, 0.5, 0, 0, 0}};
  const std::string path = dir.file("p.map");
  carmen::write_map_file(path, m);
  const std::string bytes = maptest::read_bytes(path);
  const size_t at = bytes.find("PLACES    ");
  ASSERT_NE(at, std::string::npos);
  int32_t count, type;
  std::memcpy(&count, bytes.data() + at + 10, 4);
  std::memcpy(&type, bytes.data() + at + 14, 4);
  EXPECT_EQ(count, 1);
  EXPECT_EQ(type, 1);  // CARMEN_NAMED_POSE_TYPE
  // Chunk size: 10 (description) + 4 (count) + 4 (type) + 20 (name) + 3 floats.
  int32_t size;
  std::memcpy(&size, bytes.data() + at - 4, 4);
  EXPECT_EQ(size, 10 + 4 + 4 + 20 + 12);
  const carmen::MapFile back = carmen::read_map_file(path);
  ASSERT_TRUE(back.places);
  EXPECT_EQ((*back.places)[0].type, 1);
  EXPECT_EQ((*back.places)[0].theta, 0.5);
}

}  // namespace

// Names from the file reach messages through carmen::printable: control
// bytes (a terminal escape among them) are shown as \xNN, never sent raw.
TEST(MapFileBad, ChunkNamesInMessagesArePrintable) {
  TempDir dir;
  const std::string path = dir.file("esc.map");
  write_bytes(path, maptest::kId + maptest::chunk(4, "PLACES", maptest::i32(-1), "a\x1b[2Jb", true));
  try {
    carmen::read_map_file(path);
    ADD_FAILURE() << "a negative place count was accepted";
  } catch (const FileError &e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("(named \"a\\x1b[2Jb\")"), std::string::npos) << what;
    EXPECT_EQ(what.find('\x1b'), std::string::npos) << what;
  }
  EXPECT_EQ(carmen::printable(std::string("x\ty\x7f\xc3\xa9", 6)), "x\\x09y\\x7f\xc3\xa9");
}
