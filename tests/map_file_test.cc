// carmen_compat/map_file.h: CARMEN map files, read and written whole. Damaged
// files: map_file_damage_test.cc; chunk by chunk as CARMEN writes and finds
// them: map_file_chunks_test.cc.
#include "carmen_compat/map_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>

#include "carmen_compat/error.h"
#include "map_file_test_support.h"

namespace {

using namespace mapfiletest;

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
