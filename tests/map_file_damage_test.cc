// carmen_compat/map_file.h on damaged and hostile map files: each refused
// with the file named, and no size a file claims allocated before the file
// proves it holds it.
#include "test_seed.h"
#include "carmen_compat/map_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "carmen/map_io.h"
#include "carmen_compat/error.h"
#include "largest_alloc_support.h"
#include "map_file_test_support.h"

namespace {

using namespace mapfiletest;
using alloctest::g_largest_alloc;
using alloctest::kAllocLimit;

TEST(MapFile, AllocationTrackerWorks) {
  // The allocation checks below mean something only if big allocations are seen.
  g_largest_alloc = 0;
  const MapFile m = carmen::read_map_file(map_fixture("freiburg.map"));
  EXPECT_GE(g_largest_alloc.load(), 90000 * sizeof(float));
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
// Bad input
// ---------------------------------------------------------------------------
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
