// carmen_compat/map_file.h chunk by chunk: a GRIDMAP chunk cut short and
// OFFLIMITS chunks read as CARMEN 0.7.4 reads and writes them, one chunk
// found as CARMEN finds it, and PLACES type codes.
#include "carmen_compat/map_file.h"

#include <gtest/gtest.h>

#include <cstring>

#include "carmen_compat/error.h"
#include "largest_alloc_support.h"
#include "map_file_test_support.h"

namespace {

using namespace mapfiletest;
using alloctest::g_largest_alloc;

// ---------------------------------------------------------------------------
// A GRIDMAP chunk cut short: the cells there, the rest unknown, a warning
// ---------------------------------------------------------------------------
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
