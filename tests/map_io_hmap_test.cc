// carmen/map_io.h: the hierarchical-map chunk (HMAP). The expected bytes are
// built by hand from the layout CARMEN writes (zone count, NUL-terminated
// names, link count, then per link type, degree, keys and float x y theta
// points: two per key for a door, one for an elevator).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>

#include "carmen/map_io.h"
#include "carmen_map_free.h"
#include "map_test_support.h"

namespace {

using maptest::free_hmap;

using maptest::chunk;
using maptest::f32;
using maptest::i32;
using maptest::kId;
using maptest::TempDir;

// Three zones; a door between zones 0 and 1, an elevator through all three.
struct Sample {
  char ground[7] = "ground", first[6] = "first", roof[5] = "roof";
  char *names[3] = {ground, first, roof};
  int door_keys[2] = {0, 1}, lift_keys[3] = {0, 1, 2};
  carmen_point_t door_points[4] = {{1, 2, 0.5}, {1.5, 2, 0.5}, {1, 2.5, -0.5}, {1.5, 2.5, -0.5}};
  carmen_point_t lift_points[3] = {{5, 6, 0}, {5, 6, 0.25}, {5, 6, 0.75}};
  carmen_hmap_link_t links[2] = {{CARMEN_HMAP_LINK_DOOR, 2, door_keys, 4, door_points},
                                 {CARMEN_HMAP_LINK_ELEVATOR, 3, lift_keys, 3, lift_points}};
  carmen_hmap_t hmap = {3, names, 2, links};

  static std::string points(const carmen_point_t *p, int n) {
    std::string s;
    for (int i = 0; i < n; ++i) s += f32(float(p[i].x)) + f32(float(p[i].y)) + f32(float(p[i].theta));
    return s;
  }
  std::string payload() const {
    return i32(3) + std::string("ground\0first\0roof\0", 18) + i32(2) + i32(1) + i32(2) + i32(0) + i32(1) +
           points(door_points, 4) + i32(2) + i32(3) + i32(0) + i32(1) + i32(2) + points(lift_points, 3);
  }
};

class MapIoHmap : public ::testing::TestWithParam<const char *> {
 protected:
  std::string path(const std::string &stem) const { return dir_.file(stem + GetParam()); }
  std::string content(const std::string &p) const {
    return std::string(GetParam()).size() > 4 ? maptest::gunzip_file(p) : maptest::read_bytes(p);
  }
  void write(const std::string &p, const std::string &bytes) const {
    if (std::string(GetParam()).size() > 4) {
      maptest::gzip_to_file(p, bytes);
    } else {
      maptest::write_bytes(p, bytes);
    }
  }
  TempDir dir_;
};

TEST_P(MapIoHmap, WritesCarmensBytesAndReadsThemBack) {
  Sample s;
  const std::string file = path("hmap");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_map_write_hmap_chunk(fp, &s.hmap), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  // Size: 10 + 4 + 18 names + 4 + door (8 + 8 + 48) + elevator (8 + 12 + 36).
  EXPECT_EQ(maptest::read_i32(content(file), 18), 10 + 4 + 18 + 4 + 64 + 56);
  EXPECT_EQ(content(file), kId + chunk(3, "HMAP", s.payload()));
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_HMAP_CHUNK), 10 + 4 + 18 + 4 + 64 + 56);

  carmen_hmap_t back;
  ASSERT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), 0);
  ASSERT_EQ(back.num_zones, 3);
  EXPECT_STREQ(back.zone_names[0], "ground");
  EXPECT_STREQ(back.zone_names[2], "roof");
  ASSERT_EQ(back.num_links, 2);
  EXPECT_EQ(back.links[0].type, CARMEN_HMAP_LINK_DOOR);
  EXPECT_EQ(back.links[0].num_points, 4);
  EXPECT_EQ(back.links[0].keys[1], 1);
  EXPECT_EQ(back.links[0].points[3].y, 2.5);
  EXPECT_EQ(back.links[0].points[3].theta, -0.5);
  EXPECT_EQ(back.links[1].type, CARMEN_HMAP_LINK_ELEVATOR);
  EXPECT_EQ(back.links[1].degree, 3);
  EXPECT_EQ(back.links[1].num_points, 3);
  EXPECT_EQ(back.links[1].points[2].theta, 0.75);
  free_hmap(back);
}

TEST_P(MapIoHmap, AnEmptyHmapRoundTrips) {
  carmen_hmap_t empty = {0, nullptr, 0, nullptr};
  const std::string file = path("empty");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_map_write_hmap_chunk(fp, &empty), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  EXPECT_EQ(content(file), kId + chunk(3, "HMAP", i32(0) + i32(0)));
  carmen_hmap_t back;
  ASSERT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), 0);
  EXPECT_EQ(back.num_zones, 0);
  EXPECT_EQ(back.num_links, 0);
  free_hmap(back);
}

TEST_P(MapIoHmap, BadHmapsAreRefusedOnWriting) {
  Sample s;
  const std::string file = path("bad");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  testing::internal::CaptureStderr();
  s.links[1].type = 7;
  EXPECT_EQ(carmen_map_write_hmap_chunk(fp, &s.hmap), -1);
  s.links[1].type = CARMEN_HMAP_LINK_ELEVATOR;
  s.lift_keys[2] = 3;  // there are three zones: 0..2
  EXPECT_EQ(carmen_map_write_hmap_chunk(fp, &s.hmap), -1);
  s.lift_keys[2] = 2;
  s.names[1] = nullptr;
  EXPECT_EQ(carmen_map_write_hmap_chunk(fp, &s.hmap), -1);
  EXPECT_EQ(carmen_map_write_hmap_chunk(fp, nullptr), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("unknown type 7"), std::string::npos) << err;
  EXPECT_NE(err.find("key out of range"), std::string::npos) << err;
  ASSERT_EQ(carmen_fclose(fp), 0);
  EXPECT_EQ(content(file), "");
}

TEST_P(MapIoHmap, DamagedChunksAreRefusedOnReading) {
  Sample s;
  const std::string good = s.payload();
  const std::string cases[] = {
      good.substr(0, good.size() - 4),                            // cut short
      good + "x",                                                 // bytes left over
      i32(1) + "no terminator",                                   // zone name without NUL
      i32(-1) + i32(0),                                           // negative zone count
      i32(1) + std::string("a\0", 2) + i32(1) + i32(9) + i32(0),  // unknown link type
      i32(1) + std::string("a\0", 2) + i32(1) + i32(2) + i32(1) + i32(5) + f32(0) + f32(0) + f32(0),  // key 5
      i32(0) + i32(1000000),  // more links than bytes
  };
  carmen_hmap_t back;
  std::memset(&back, 0, sizeof back);
  for (const std::string &payload : cases) {
    const std::string file = path("damaged");
    write(file, kId + chunk(3, "HMAP", payload));
    testing::internal::CaptureStderr();
    EXPECT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), -1);
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find(file), std::string::npos) << err;
    EXPECT_EQ(back.zone_names, nullptr);  // cleared: no stale pointer
    EXPECT_EQ(back.num_zones, 0);
  }
  const std::string none = path("none");
  write(none, kId);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_hmap_chunk(none.c_str(), &back), -1);
  EXPECT_EQ(carmen_map_read_hmap_chunk(nullptr, &back), -1);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("has no HMAP chunk"), std::string::npos);
}

// CARMEN's reader finds the first HMAP chunk, named or not, and skips its
// name; a damaged chunk after it does not matter.
TEST_P(MapIoHmap, TheFirstHmapIsReadNamedOrNot) {
  Sample s;
  const std::string file = path("named_hmap");
  const std::string damaged_after = std::string(1, '\x66') + i32(0x7ffffff0) + "JUNK      ";
  write(file, kId + chunk(3, "HMAP", s.payload(), "zones", true) + chunk(3, "HMAP", i32(0) + i32(0)) +
                  damaged_after);
  carmen_hmap_t back;
  std::memset(&back, 0x5a, sizeof back);
  ASSERT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &back), 0);
  ASSERT_EQ(back.num_zones, 3);
  EXPECT_STREQ(back.zone_names[0], "ground");
  EXPECT_STREQ(back.zone_names[2], "roof");
  ASSERT_EQ(back.num_links, 2);
  EXPECT_EQ(back.links[1].type, CARMEN_HMAP_LINK_ELEVATOR);
  EXPECT_EQ(back.links[1].points[2].theta, 0.75);
  free_hmap(back);
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_HMAP_CHUNK), int(10 + 6 + s.payload().size()));
}

INSTANTIATE_TEST_SUITE_P(PlainAndGzip, MapIoHmap, ::testing::Values(".map", ".map.gz"), [](const auto &info) {
  return std::string(info.param).size() > 4 ? "gzip" : "plain";
});

}  // namespace
