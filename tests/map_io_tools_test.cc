// carmen/map_io.h: the named creator and gridmap-config readers, the file
// utilities (copy_comments, strip, vstrip, name_chunk), PPM output, off-limits
// into a map, and CARMEN's macros. Expected bytes are built by hand from the
// format notes (maptest helpers), never taken from the library.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <utility>
#include <vector>

#include "carmen/map_io.h"
#include "carmen_map_free.h"
#include "map_test_support.h"

namespace {

using maptest::free_map;

using maptest::chunk;
using maptest::f32;
using maptest::f64;
using maptest::field;
using maptest::i32;
using maptest::kId;
using maptest::read_bytes;
using maptest::TempDir;

// The payload of a GRIDMAP chunk: sizes, resolution, cells x-major.
std::string grid_payload(int sx, int sy, float res, const std::vector<float> &cells) {
  std::string p = i32(sx) + i32(sy) + f32(res);
  for (float v : cells) p += f32(v);
  return p;
}

// A map file from hand-built pieces (plain or, for ".gz", gzipped).
void write_map(const std::string &path, const std::string &bytes) {
  if (path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0) {
    maptest::gzip_to_file(path, bytes);
  } else {
    maptest::write_bytes(path, bytes);
  }
}

std::string content(const std::string &path) {
  return path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0 ? maptest::gunzip_file(path)
                                                                         : read_bytes(path);
}

TEST(MapIoMacros, AreCarmensValues) {
  EXPECT_EQ(CARMEN_MAP_NO_CHUNK, 0);
  EXPECT_EQ(CARMEN_MAP_NAMED_CHUNK_FLAG, 128);
  EXPECT_NE(CARMEN_MAP_CHUNK_IS_NAMED(0x81), 0);
  EXPECT_EQ(CARMEN_MAP_CHUNK_IS_NAMED(0x01), 0);
  EXPECT_EQ(CARMEN_MAP_CHUNK_IS_NAMED(CARMEN_MAP_GLOBAL_OFFSET_CHUNK), 0);
#if !defined(CARMEN_OFFLIMITS_POINT_ID) || !defined(CARMEN_OFFLIMITS_LINE_ID) || \
    !defined(CARMEN_OFFLIMITS_RECT_ID)
  ADD_FAILURE() << "CARMEN_OFFLIMITS_*_ID must be macros, as in CARMEN's map.h";
#endif
  EXPECT_EQ(CARMEN_OFFLIMITS_POINT_ID, 0);
  EXPECT_EQ(CARMEN_OFFLIMITS_LINE_ID, 1);
  EXPECT_EQ(CARMEN_OFFLIMITS_RECT_ID, 2);
  EXPECT_EQ(CARMEN_HMAP_LINK_DOOR, 1);
  EXPECT_EQ(CARMEN_HMAP_LINK_ELEVATOR, 2);
  EXPECT_EQ(CARMEN_NAMED_POSITION_TYPE, 0);
  EXPECT_EQ(CARMEN_NAMED_POSE_TYPE, 1);
  EXPECT_EQ(CARMEN_LOCALIZATION_INIT_TYPE, 2);
}

class MapIoTools : public ::testing::TestWithParam<const char *> {
 protected:
  std::string path(const std::string &stem) const { return dir_.file(stem + GetParam()); }
  TempDir dir_;
};

TEST_P(MapIoTools, NamedCreatorChunk) {
  const std::string file = path("creator");
  const time_t before = std::time(nullptr);
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_map_write_named_creator_chunk(fp, "robot2", "origin text", "desc text"), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  // type 32|128, size 10 + "robot2\0" + user 10 + time_t + 80 + 80.
  const std::string bytes = content(file);
  const int tbytes = int(sizeof(time_t));
  ASSERT_EQ(bytes.size(), 17u + 5 + 10 + 7 + 170 + size_t(tbytes));
  EXPECT_EQ(uint8_t(bytes[17]), 0xA0);
  EXPECT_EQ(maptest::read_i32(bytes, 18), 10 + 7 + 170 + tbytes);
  EXPECT_EQ(bytes.substr(22, 17), field("CREATOR", 10) + std::string("robot2\0", 7));
  EXPECT_EQ(bytes.substr(39 + 10 + tbytes, 80), field("origin text", 80));

  time_t when = 0;
  char user[11], origin[81], desc[81];
  ASSERT_EQ(carmen_map_read_named_creator_chunk(file.c_str(), "robot2", &when, user, origin, desc), 0);
  EXPECT_GE(when, before);
  EXPECT_STREQ(origin, "origin text");
  EXPECT_STREQ(desc, "desc text");
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_named_creator_chunk(file.c_str(), "robot3", &when, user, origin, desc), -1);
  EXPECT_EQ(carmen_map_write_named_creator_chunk(fp, nullptr, "o", "d"), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find(file), std::string::npos) << err;
  EXPECT_NE(err.find("robot3"), std::string::npos) << err;
}

TEST_P(MapIoTools, NamedGridmapConfigNamesTheChunk) {
  const std::string file = path("config");
  write_map(file,
            kId + chunk(1, "GRIDMAP", grid_payload(1, 1, 0.5f, {0.5f}), "small", true) +
                chunk(1, "GRIDMAP", grid_payload(3, 2, 0.25f, std::vector<float>(6, 0.0f)), "big", true));
  carmen_map_config_t config;
  ASSERT_EQ(carmen_map_read_named_gridmap_config(file.c_str(), "big", &config), 0);
  EXPECT_EQ(config.x_size, 3);
  EXPECT_EQ(config.y_size, 2);
  EXPECT_EQ(config.resolution, 0.25);
  EXPECT_STREQ(config.map_name, "big");  // CARMEN's named reader stores the chunk name
  std::free(config.map_name);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_named_gridmap_config(file.c_str(), "huge", &config), -1);
  EXPECT_EQ(carmen_map_read_named_gridmap_config(file.c_str(), "big", nullptr), -1);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("huge"), std::string::npos);
}

TEST_P(MapIoTools, NamedPlacesKeepCarmensTypeCodes) {
  const std::string file = path("places");
  carmen_place_t places[3];
  std::memset(places, 0, sizeof places);
  places[0] = {CARMEN_NAMED_POSITION_TYPE, 0, "door", 1.5, 2.5, 0, 0, 0, 0};
  places[1] = {CARMEN_NAMED_POSE_TYPE, 0, "desk", 3.0, 4.0, 0.5, 0, 0, 0};
  places[2] = {CARMEN_LOCALIZATION_INIT_TYPE, 0, "start", 5, 6, 0.25, 0.125, 0.0625, 1};
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_map_write_named_places_chunk(fp, "floor1", places, 3), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  const std::string payload = i32(3) + i32(0) + field("door", 20) + f32(1.5f) + f32(2.5f) + i32(1) +
                              field("desk", 20) + f32(3) + f32(4) + f32(0.5f) + i32(2) + field("start", 20) +
                              f32(5) + f32(6) + f32(0.25f) + f32(0.125f) + f32(0.0625f) + f32(1);
  EXPECT_EQ(content(file), kId + chunk(4, "PLACES", payload, "floor1", true));
  carmen_map_placelist_t list = {nullptr, 0};
  ASSERT_EQ(carmen_map_read_named_places_chunk(file.c_str(), "floor1", &list), 0);
  ASSERT_EQ(list.num_places, 3);
  EXPECT_EQ(list.places[0].type, CARMEN_NAMED_POSITION_TYPE);
  EXPECT_EQ(list.places[1].theta, 0.5);
  EXPECT_EQ(list.places[2].theta_std, 1.0);
  std::free(list.places);
}

// A map with comments, a grid, places (unnamed and named) and an offset.
struct Pieces {
  std::string comments = "# first\n#second line\n";
  std::string grid = chunk(1, "GRIDMAP", grid_payload(1, 2, 0.1f, {0.5f, -1.0f}));
  std::string places = chunk(4, "PLACES", i32(1) + i32(0) + field("a", 20) + f32(1) + f32(2));
  std::string named_places = chunk(4, "PLACES", i32(0), "other", true);
  std::string offset = chunk(64, "OFFSET", f64(1) + f64(2) + f64(3));
  std::string all() const { return comments + kId + grid + places + named_places + offset; }
};

// carmen_map_strip / vstrip / copy_comments from file `in` to file `out`.
template <typename F>
int run_on(const std::string &in, const std::string &out, F &&call) {
  carmen_FILE *fi = carmen_fopen(in.c_str(), "r");
  carmen_FILE *fo = carmen_fopen(out.c_str(), "w");
  const int rc = call(fi, fo);
  carmen_fclose(fi);
  carmen_fclose(fo);
  return rc;
}

TEST_P(MapIoTools, CopyCommentsCopiesCommentsAndId) {
  const Pieces p;
  write_map(path("in"), p.all());
  EXPECT_EQ(run_on(path("in"), path("out"), carmen_map_copy_comments), 0);
  EXPECT_EQ(content(path("out")), p.comments + kId);
  write_map(path("bad"), "# only a comment\nNOTAMAP");
  testing::internal::CaptureStderr();
  EXPECT_EQ(run_on(path("bad"), path("out"), carmen_map_copy_comments), -1);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("not a CARMEN map"), std::string::npos);
}

// Named chunks are never stripped, as in CARMEN (its table is indexed by the
// raw type byte, so type | 0x80 is never in it). This test used to expect the
// named places to go with their type.
TEST_P(MapIoTools, StripRemovesTheUnnamedChunksOfTheType) {
  const Pieces p;
  write_map(path("in"), p.all());
  EXPECT_EQ(
      run_on(path("in"), path("out"),
             [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_strip(i, o, CARMEN_MAP_PLACES_CHUNK); }),
      0);
  EXPECT_EQ(content(path("out")), p.comments + kId + p.grid + p.named_places + p.offset);
  EXPECT_EQ(run_on(path("in"), path("out"),
                   [](carmen_FILE *i, carmen_FILE *o) {
                     return carmen_map_vstrip(i, o, 2, CARMEN_MAP_GRIDMAP_CHUNK,
                                              CARMEN_MAP_GLOBAL_OFFSET_CHUNK);
                   }),
            0);
  EXPECT_EQ(content(path("out")), p.comments + kId + p.places + p.named_places);
  EXPECT_EQ(run_on(path("in"), path("out"),
                   [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_vstrip(i, o, 0); }),
            0);
  EXPECT_EQ(content(path("out")), p.all());
}

// A map like the ones CARMEN's own maptool strips: comments, creator, an
// unnamed gridmap, a named second gridmap, unnamed and named places and a
// named hmap. The expected size after stripping is summed from the chunk
// sizes (5 header bytes + the size field each), not taken from the library.
struct RichMap {
  std::string comments = "# rich map\n";
  std::string creator =
      chunk(32, "CREATOR", field("me", 10) + i32(1000000000) + field("origin", 80) + field("desc", 80));
  std::string grid = chunk(1, "GRIDMAP", grid_payload(2, 3, 0.1f, {0, 0.25f, 0.5f, 0.75f, 1, -1}));
  std::string named_grid = chunk(1, "GRIDMAP", grid_payload(3, 2, 0.2f, {1, 1, 1, 0, 0, 0}), "level2", true);
  std::string places = chunk(4, "PLACES", i32(1) + i32(0) + field("a", 20) + f32(1) + f32(2));
  std::string named_places = chunk(4, "PLACES", i32(0), "zone2", true);
  std::string named_hmap = chunk(3, "HMAP", i32(1) + std::string("z\0", 2) + i32(0), "zones", true);
  std::string all() const {
    return comments + kId + creator + grid + named_grid + places + named_places + named_hmap;
  }
};

size_t chunk_bytes(const std::string &c) { return 5 + size_t(maptest::read_i32(c, 1)); }

TEST_P(MapIoTools, StripAndVstripKeepEveryNamedChunk) {
  const RichMap m;
  write_map(path("rich"), m.all());
  EXPECT_EQ(run_on(path("rich"), path("o"),
                   [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_strip(i, o, CARMEN_MAP_GRIDMAP_CHUNK); }),
            0);
  const std::string out = content(path("o"));
  const size_t want = m.comments.size() + kId.size() + chunk_bytes(m.creator) + chunk_bytes(m.named_grid) +
                      chunk_bytes(m.places) + chunk_bytes(m.named_places) + chunk_bytes(m.named_hmap);
  EXPECT_EQ(out.size(), want);
  EXPECT_EQ(out, m.comments + kId + m.creator + m.named_grid + m.places + m.named_places + m.named_hmap);
  // After the strip, the named gridmap is the first one: what CARMEN's
  // readers (and ours) read from the stripped file.
  carmen_map_config_t config;
  ASSERT_EQ(carmen_map_read_gridmap_config(path("o").c_str(), &config), 0);
  EXPECT_EQ(config.x_size, 3);
  EXPECT_EQ(config.y_size, 2);
  std::free(config.map_name);

  // vstrip of every type in the file: only the named chunks are left.
  EXPECT_EQ(run_on(path("rich"), path("o2"),
                   [](carmen_FILE *i, carmen_FILE *o) {
                     return carmen_map_vstrip(i, o, 4, CARMEN_MAP_CREATOR_CHUNK, CARMEN_MAP_GRIDMAP_CHUNK,
                                              CARMEN_MAP_PLACES_CHUNK, CARMEN_MAP_HMAP_CHUNK);
                   }),
            0);
  const std::string out2 = content(path("o2"));
  EXPECT_EQ(out2.size(), m.comments.size() + kId.size() + chunk_bytes(m.named_grid) + chunk_bytes(m.named_places) +
                             chunk_bytes(m.named_hmap));
  EXPECT_EQ(out2, m.comments + kId + m.named_grid + m.named_places + m.named_hmap);
}

// What maptool add_place does: strip the unnamed places, then append a new
// unnamed places chunk. The named places of other zones survive.
TEST_P(MapIoTools, AddPlaceLikeMaptoolKeepsNamedPlaces) {
  const RichMap m;
  write_map(path("rich"), m.all());
  carmen_map_placelist_t list;
  ASSERT_EQ(carmen_map_read_places_chunk(path("rich").c_str(), &list), 0);
  ASSERT_EQ(list.num_places, 1);
  list.places = static_cast<carmen_place_p>(std::realloc(list.places, 2 * sizeof(carmen_place_t)));
  ASSERT_NE(list.places, nullptr);
  std::memset(&list.places[1], 0, sizeof list.places[1]);
  std::strcpy(list.places[1].name, "p");
  list.places[1].x = 1;
  list.places[1].y = 2;
  list.num_places = 2;
  carmen_FILE *fi = carmen_fopen(path("rich").c_str(), "r");
  carmen_FILE *fo = carmen_fopen(path("new").c_str(), "w");
  ASSERT_EQ(carmen_map_strip(fi, fo, CARMEN_MAP_PLACES_CHUNK), 0);
  ASSERT_EQ(carmen_map_write_places_chunk(fo, list.places, list.num_places), 0);
  carmen_fclose(fi);
  carmen_fclose(fo);
  std::free(list.places);
  const std::string places2 = chunk(4, "PLACES", i32(2) + i32(0) + field("a", 20) + f32(1) + f32(2) + i32(0) +
                                                     field("p", 20) + f32(1) + f32(2));
  EXPECT_EQ(content(path("new")),
            m.comments + kId + m.creator + m.grid + m.named_grid + m.named_places + m.named_hmap + places2);
  carmen_map_placelist_t named = {nullptr, 0};
  ASSERT_EQ(carmen_map_read_named_places_chunk(path("new").c_str(), "zone2", &named), 0);
  EXPECT_EQ(named.num_places, 0);
  std::free(named.places);
}

TEST_P(MapIoTools, StripRefusesBadTypesAndTruncatedInput) {
  const Pieces p;
  write_map(path("in"), p.all());
  testing::internal::CaptureStderr();
  EXPECT_EQ(run_on(path("in"), path("out"),
                   [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_strip(i, o, 200); }),
            -1);
  EXPECT_EQ(run_on(path("in"), path("out"),
                   [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_vstrip(i, o, -1); }),
            -1);
  const std::string all = p.all();
  write_map(path("cut"), all.substr(0, all.size() - 3));
  EXPECT_EQ(run_on(path("cut"), path("out"),
                   [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_strip(i, o, 4); }),
            -1);
  EXPECT_EQ(carmen_map_strip(nullptr, nullptr, 4), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("200"), std::string::npos) << err;
  EXPECT_NE(err.find("ends inside a chunk"), std::string::npos) << err;
}

TEST_P(MapIoTools, NameChunkAppendsANamedCopy) {
  const Pieces p;
  const std::string file = path("name");
  write_map(file, p.all());
  ASSERT_EQ(carmen_map_name_chunk(file.c_str(), file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK, "copy"), 0);
  const std::string named = chunk(1, "GRIDMAP", grid_payload(1, 2, 0.1f, {0.5f, -1.0f}), "copy", true);
  EXPECT_EQ(content(file), p.all() + named);
  carmen_map_t map;
  std::memset(&map, 0, sizeof map);
  ASSERT_EQ(carmen_map_read_named_gridmap_chunk(file.c_str(), "copy", &map), 0);
  EXPECT_EQ(map.map[0][1], -1.0f);
  free_map(map);

  testing::internal::CaptureStderr();
  // The name is taken now; a named first chunk cannot be named again; a
  // missing type or output file is refused.
  EXPECT_EQ(carmen_map_name_chunk(file.c_str(), file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK, "copy"), -1);
  write_map(path("named_first"), kId + p.named_places);
  EXPECT_EQ(carmen_map_name_chunk(path("named_first").c_str(), file.c_str(), CARMEN_MAP_PLACES_CHUNK, "x"),
            -1);
  EXPECT_EQ(carmen_map_name_chunk(file.c_str(), file.c_str(), CARMEN_MAP_HMAP_CHUNK, "x"), -1);
  EXPECT_EQ(carmen_map_name_chunk(file.c_str(), path("absent").c_str(), CARMEN_MAP_GRIDMAP_CHUNK, "x"), -1);
  EXPECT_EQ(carmen_map_name_chunk(file.c_str(), file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK, ""), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("already has a GRIDMAP chunk named \"copy\""), std::string::npos) << err;
  EXPECT_NE(err.find("already named"), std::string::npos) << err;
  EXPECT_NE(err.find(path("absent")), std::string::npos) << err;
  EXPECT_EQ(content(file), p.all() + named);  // nothing appended by the refusals
}

// A 1-cell-per-value grid file with an OFFLIMITS chunk, read back.
carmen_map_t read_with_offlimits(const std::string &file, int sx, int sy, const std::vector<float> &cells,
                                 const std::string &offlimits_payload) {
  write_map(file, kId + chunk(1, "GRIDMAP", grid_payload(sx, sy, 1.0f, cells)) +
                      chunk(2, "OFFLIMITS", offlimits_payload));
  carmen_map_t map;
  std::memset(&map, 0, sizeof map);
  EXPECT_EQ(carmen_map_read_gridmap_chunk(file.c_str(), &map), 0);
  return map;
}

TEST_P(MapIoTools, OfflimitsIntoMapAddsTwoToEveryMarkedCell) {
  const std::string file = path("offl");
  std::vector<float> cells(6 * 5, 0.25f);
  cells[0] = -1.0f;  // cell (0, 0): -1 + 2 = 1, as CARMEN computes it
  // Points (0,0) and (10,10) (outside), the line (1,1)-(4,3), the rectangle
  // (3,0)-(4,1).
  const std::string payload = i32(2) + i32(0) + i32(0) + i32(10) + i32(10) + i32(1) + i32(1) + i32(1) +
                              i32(4) + i32(3) + i32(1) + i32(3) + i32(0) + i32(4) + i32(1);
  carmen_map_t map = read_with_offlimits(file, 6, 5, cells, payload);
  ASSERT_EQ(carmen_map_read_offlimits_chunk_into_map(file.c_str(), &map), 0);
  // CARMEN's Bresenham from (1,1) to (4,3), worked by hand: (1,1) (2,2) (3,2) (4,3).
  const std::vector<std::pair<int, int>> marked = {{1, 1}, {2, 2}, {3, 2}, {4, 3},
                                                   {3, 0}, {3, 1}, {4, 0}, {4, 1}};
  for (int x = 0; x < 6; ++x) {
    for (int y = 0; y < 5; ++y) {
      const bool hit = std::find(marked.begin(), marked.end(), std::make_pair(x, y)) != marked.end();
      const float want = (x == 0 && y == 0) ? 1.0f : hit ? 2.25f : 0.25f;
      EXPECT_EQ(map.map[x][y], want) << x << "," << y;
    }
  }
  free_map(map);
}

TEST_P(MapIoTools, OfflimitsLineFollowsCarmensSteepReversedWalk) {
  const std::string file = path("steep");
  // The line (0,4)-(1,0): steep, flipped, walked downwards. By hand, with
  // CARMEN's rules: (0,4) (0,3) (0,2) (1,1) (1,0).
  carmen_map_t map = read_with_offlimits(file, 2, 5, std::vector<float>(10, 0.0f),
                                         i32(0) + i32(1) + i32(0) + i32(4) + i32(1) + i32(0) + i32(0));
  ASSERT_EQ(carmen_map_read_offlimits_chunk_into_map(file.c_str(), &map), 0);
  const float want[2][5] = {{0, 0, 2, 2, 2}, {2, 2, 0, 0, 0}};
  for (int x = 0; x < 2; ++x) {
    for (int y = 0; y < 5; ++y) EXPECT_EQ(map.map[x][y], want[x][y]) << x << "," << y;
  }
  free_map(map);
}

// Off-limits written by CARMEN's own writers (map_test_support.h): its line
// loop leaves out the second line, its named writer's size says 22. What
// maptool toppm, strip and rotate do with them: mark the cells, and copy
// them (as the chunks CARMEN meant, so CARMEN reads the copy right too) or
// strip them, with the chunks after them intact.
TEST_P(MapIoTools, OfflimitsInCarmensLayoutsSurviveToppmStripAndRotate) {
  const std::string file = path("carmen_offl");
  const std::vector<maptest::CarmenOffItem> items = {
      {0, 0, 0, 0, 0}, {1, 1, 1, 4, 3}, {2, 3, 0, 4, 1}, {1, 0, 4, 1, 4}};
  const std::string grid = chunk(1, "GRIDMAP", grid_payload(6, 5, 1.0f, std::vector<float>(30, 0.25f)));
  const std::string scans = chunk(16, "LASERSCANS", i32(1) + f32(1) + f32(2) + f32(3) + i32(1) + f32(4));
  write_map(file, kId + grid + maptest::carmen_offlimits_chunk(items) + scans +
                      maptest::carmen_offlimits_chunk(items, "zone", true));
  // toppm: the point, the line CARMEN wrote and the rectangle are marked.
  carmen_map_t map;
  std::memset(&map, 0, sizeof map);
  ASSERT_EQ(carmen_map_read_gridmap_chunk(file.c_str(), &map), 0);
  testing::internal::CaptureStderr();
  const int rc = carmen_map_read_offlimits_chunk_into_map(file.c_str(), &map);
  const std::string err = testing::internal::GetCapturedStderr();
  ASSERT_EQ(rc, 0) << err;
  EXPECT_NE(err.find("warning: the OFFLIMITS chunk at byte 164"), std::string::npos) << err;
  const std::vector<std::pair<int, int>> marked = {{0, 0}, {1, 1}, {2, 2}, {3, 2}, {4, 3},
                                                   {3, 0}, {3, 1}, {4, 0}, {4, 1}};
  for (int x = 0; x < 6; ++x) {
    for (int y = 0; y < 5; ++y) {
      const bool hit = std::find(marked.begin(), marked.end(), std::make_pair(x, y)) != marked.end();
      EXPECT_EQ(map.map[x][y], hit ? 2.25f : 0.25f) << x << "," << y;
    }
  }
  free_map(map);
  // strip (of a type the file lacks): every chunk copied, the off-limits as
  // CARMEN meant them.
  const std::string meant = i32(1) + i32(0) + i32(0) + i32(1) + i32(1) + i32(1) + i32(4) + i32(3) + i32(1) +
                            i32(3) + i32(0) + i32(4) + i32(1);
  const std::string fixed = chunk(2, "OFFLIMITS", meant);
  const std::string fixed_named = chunk(2, "OFFLIMITS", meant, "zone", true);
  testing::internal::CaptureStderr();
  EXPECT_EQ(run_on(file, path("out"),
                   [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_strip(i, o, CARMEN_MAP_PLACES_CHUNK); }),
            0);
  EXPECT_EQ(content(path("out")), kId + grid + fixed + scans + fixed_named);
  // rotate strips the gridmap, the off-limits and the places before writing
  // its own: the scans stay, and the named chunk (never stripped).
  EXPECT_EQ(run_on(file, path("rot"),
                   [](carmen_FILE *i, carmen_FILE *o) {
                     return carmen_map_vstrip(i, o, 3, CARMEN_MAP_GRIDMAP_CHUNK, CARMEN_MAP_OFFLIMITS_CHUNK,
                                              CARMEN_MAP_PLACES_CHUNK);
                   }),
            0);
  EXPECT_EQ(content(path("rot")), kId + scans + fixed_named);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

// A gridmap cut short is read (map_file.h), so rotate, which strips it
// before writing its own, must get past it: stripped, it goes as far as the
// file does, as CARMEN's fseek takes it. Copied, it is still an error, as in
// CARMEN, whose copy fails there too.
TEST_P(MapIoTools, StripDropsAGridmapCutShort) {
  const Pieces p;
  const std::string file = path("short");
  write_map(file, kId + p.places + p.grid.substr(0, p.grid.size() - 3));
  EXPECT_EQ(run_on(file, path("out"),
                   [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_strip(i, o, CARMEN_MAP_GRIDMAP_CHUNK); }),
            0);
  EXPECT_EQ(content(path("out")), kId + p.places);
  testing::internal::CaptureStderr();
  EXPECT_EQ(run_on(file, path("out"),
                   [](carmen_FILE *i, carmen_FILE *o) { return carmen_map_strip(i, o, CARMEN_MAP_PLACES_CHUNK); }),
            -1);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("ends inside a chunk"), std::string::npos);
}

TEST_P(MapIoTools, OfflimitsIntoMapFailsAsCarmenDoes) {
  const std::string file = path("empty_offl");
  carmen_map_t map = read_with_offlimits(file, 1, 1, {0.5f}, i32(0) + i32(0) + i32(0));
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_offlimits_chunk_into_map(file.c_str(), &map), -1);  // empty chunk
  EXPECT_EQ(carmen_map_read_offlimits_chunk_into_map(file.c_str(), nullptr), -1);
  std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("empty"), std::string::npos) << err;
  // No off-limits chunk: -1 without a word, as CARMEN's (maptool's toppm
  // asks on every map; this used to print a line each time).
  write_map(path("none"), kId + chunk(1, "GRIDMAP", grid_payload(1, 1, 1.0f, {0.5f})));
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_offlimits_chunk_into_map(path("none").c_str(), &map), -1);
  err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "");
  EXPECT_EQ(map.map[0][0], 0.5f);
  free_map(map);
}

INSTANTIATE_TEST_SUITE_P(PlainAndGzip, MapIoTools, ::testing::Values(".map", ".map.gz"),
                         [](const auto &info) {
                           return std::string(info.param).size() > 4 ? "gzip" : "plain";
                         });

// ---- PPM ---------------------------------------------------------------------
struct Ppm {
  int width = 0, height = 0, maxval = 0;
  std::string pixels;
};

// Parses a binary PPM with single-space/newline separators (what CARMEN writes).
Ppm parse_ppm(const std::string &bytes) {
  Ppm p;
  char magic[3] = {};
  int consumed = 0;
  if (std::sscanf(bytes.c_str(), "%2s %d %d %d%n", magic, &p.width, &p.height, &p.maxval, &consumed) != 4 ||
      std::string(magic) != "P6") {
    ADD_FAILURE() << "not a P6 header";
    return p;
  }
  p.pixels = bytes.substr(size_t(consumed) + 1);  // one whitespace byte after maxval
  return p;
}

TEST(MapIoPpm, ColoursAndOrientationAreCarmens) {
  TempDir dir;
  float cells[3][2] = {{-1.0f, 0.5f}, {0.0f, 0.25f}, {1.0f, 2.5f}};  // [x][y]
  float *rows[3] = {cells[0], cells[1], cells[2]};
  carmen_map_t map;
  map.config = {3, 2, 0.1, nullptr};
  map.complete_map = cells[0];
  map.map = rows;
  const std::string file = dir.file("map.ppm");
  ASSERT_EQ(carmen_map_write_to_ppm(&map, file.c_str()), 0);
  const std::string bytes = read_bytes(file);
  EXPECT_EQ(bytes.substr(0, 11), "P6\n3 2\n255\n");
  const Ppm p = parse_ppm(bytes);
  EXPECT_EQ(p.width, 3);
  EXPECT_EQ(p.height, 2);
  EXPECT_EQ(p.maxval, 255);
  // Top row is y = 1: 0.5 -> 255 - 127.5 = 127; 0.25 -> 191.25 = 191;
  // 2.5 (off-limits 0.5) -> (255, 127, 127). Then y = 0: -1 blue; 0 white; 1 black.
  const unsigned char want[] = {127, 127, 127, 191, 191, 191, 255, 127, 127,
                                0,   0,   255, 255, 255, 255, 0,   0,   0};
  ASSERT_EQ(p.pixels.size(), sizeof want);
  for (size_t i = 0; i < sizeof want; ++i) EXPECT_EQ(uint8_t(p.pixels[i]), want[i]) << "byte " << i;
}

TEST(MapIoPpm, BadArgumentsAreRefused) {
  TempDir dir;
  carmen_map_t map;
  std::memset(&map, 0, sizeof map);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_write_to_ppm(nullptr, dir.file("a.ppm").c_str()), -1);
  EXPECT_EQ(carmen_map_write_to_ppm(&map, dir.file("b.ppm").c_str()), -1);
  float cell = 0.5f;
  float *row = &cell;
  map.config = {1, 1, 0.1, nullptr};
  map.map = &row;
  EXPECT_EQ(carmen_map_write_to_ppm(&map, "/nonexistent/dir/c.ppm"), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("/nonexistent/dir/c.ppm"), std::string::npos) << err;
  EXPECT_FALSE(maptest::file_exists(dir.file("a.ppm")));
}

}  // namespace
