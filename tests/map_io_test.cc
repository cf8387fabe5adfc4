// carmen/map_io.h: CARMEN's C API for map files, written and read back,
// CARMEN's comment block and the map-server stand-ins. Named chunks read by
// the unnamed readers, failed reads and damaged maps: map_io_reading_test.cc.
#include "carmen/map_io.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include "map_io_test_support.h"

namespace {

using namespace mapiotest;

TEST_P(MapIo, WriteAllThenReadEveryChunk) {
  const std::string file = path("all");
  CGrid grid(3, 2);
  for (int x = 0; x < 3; ++x) {
    for (int y = 0; y < 2; ++y)
      grid.rows[size_t(x)][y] = (x == 0 && y == 0) ? -1.0f : 0.125f * float(x + 3 * y);
  }
  carmen_place_t places[2];
  std::memset(places, 0, sizeof places);
  places[0].type = CARMEN_NAMED_POSE_TYPE;
  std::strcpy(places[0].name, "kitchen");
  places[0].x = 1.5;
  places[0].y = 2.5;
  places[0].theta = 0.25;
  places[1].type = CARMEN_LOCALIZATION_INIT_TYPE;
  std::strcpy(places[1].name, "start");
  places[1].x_std = 0.5;
  places[1].theta_std = 0.125;
  carmen_offlimits_t offl[3] = {{CARMEN_OFFLIMITS_RECT_ID, 1, 2, 3, 4},
                                {CARMEN_OFFLIMITS_POINT_ID, 5, 6, 0, 0},
                                {CARMEN_OFFLIMITS_LINE_ID, 7, 8, 9, 10}};
  float ranges[3] = {1.0f, 2.0f, 4.0f};
  carmen_laser_scan_t scan = {0.5, -0.5, 1.0, 3, ranges};

  const time_t before = std::time(nullptr);
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_all(fp, grid.rows.data(), 3, 2, 0.5, "log.clf", "a test", "creator origin",
                                 "creator desc", places, 2, offl, 3, &scan, 1),
            0);
  carmen_global_offset_t off = {10.0, -20.0, 0.5};
  ASSERT_EQ(carmen_map_write_global_offset_chunk(fp, &off), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);

  EXPECT_EQ(carmen_map_file(file.c_str()), 1);

  carmen_map_t map;
  std::memset(&map, 0, sizeof map);
  ASSERT_EQ(carmen_map_read_gridmap_chunk(file.c_str(), &map), 0);
  EXPECT_EQ(map.config.x_size, 3);
  EXPECT_EQ(map.config.y_size, 2);
  EXPECT_EQ(map.config.resolution, 0.5);
  EXPECT_EQ(map.map[0][0], -1.0f);
  EXPECT_EQ(map.map[2][1], 0.125f * 5);
  EXPECT_EQ(map.complete_map[2 * 2 + 1], 0.125f * 5);  // x-major
  EXPECT_EQ(map.map[1], map.complete_map + 2);
  EXPECT_STREQ(map.config.map_name, file.c_str());  // CARMEN's reader sets the file name
  std::free(map.map);
  std::free(map.complete_map);
  std::free(map.config.map_name);

  carmen_map_config_t config;
  ASSERT_EQ(carmen_map_read_gridmap_config(file.c_str(), &config), 0);
  EXPECT_EQ(config.x_size, 3);
  EXPECT_EQ(config.y_size, 2);
  EXPECT_STREQ(config.map_name, file.c_str());
  std::free(config.map_name);

  time_t when = 0;
  char user[11], origin[81], desc[81];
  ASSERT_EQ(carmen_map_read_creator_chunk(file.c_str(), &when, user, origin, desc), 0);
  EXPECT_GE(when, before);
  EXPECT_LE(when, std::time(nullptr));
  EXPECT_STREQ(origin, "creator origin");
  EXPECT_STREQ(desc, "creator desc");

  carmen_map_placelist_t plist = {nullptr, 0};
  ASSERT_EQ(carmen_map_read_places_chunk(file.c_str(), &plist), 0);
  ASSERT_EQ(plist.num_places, 2);
  EXPECT_STREQ(plist.places[0].name, "kitchen");
  EXPECT_EQ(plist.places[0].type, CARMEN_NAMED_POSE_TYPE);
  EXPECT_EQ(plist.places[0].theta, 0.25);
  EXPECT_EQ(plist.places[1].x_std, 0.5);
  EXPECT_EQ(plist.places[1].theta_std, 0.125);
  std::free(plist.places);

  carmen_offlimits_p ol = nullptr;
  int nol = 0;
  ASSERT_EQ(carmen_map_read_offlimits_chunk(file.c_str(), &ol, &nol), 0);
  ASSERT_EQ(nol, 3);
  // Points, then lines, then rectangles.
  EXPECT_EQ(ol[0].type, CARMEN_OFFLIMITS_POINT_ID);
  EXPECT_EQ(ol[0].y1, 6);
  EXPECT_EQ(ol[1].type, CARMEN_OFFLIMITS_LINE_ID);
  EXPECT_EQ(ol[1].x2, 9);
  EXPECT_EQ(ol[2].type, CARMEN_OFFLIMITS_RECT_ID);
  EXPECT_EQ(ol[2].y2, 4);
  std::free(ol);

  carmen_laser_scan_p scans = nullptr;
  int nscans = 0;
  ASSERT_EQ(carmen_map_read_laserscans_chunk(file.c_str(), &scans, &nscans), 0);
  ASSERT_EQ(nscans, 1);
  EXPECT_EQ(scans[0].num_readings, 3);
  EXPECT_EQ(scans[0].range[2], 4.0f);
  EXPECT_EQ(scans[0].theta, 1.0);
  std::free(scans[0].range);
  std::free(scans);

  carmen_global_offset_t back;
  ASSERT_EQ(carmen_map_read_global_offset_chunk(file.c_str(), &back), 0);
  EXPECT_EQ(back.x, 10.0);
  EXPECT_EQ(back.y, -20.0);
  EXPECT_EQ(back.theta, 0.5);

  // Creator chunk size: 180 + sizeof(time_t); gridmap 10 + 12 + 4*6.
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_CREATOR_CHUNK), 180 + int(sizeof(time_t)));
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK), 46);
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_HMAP_CHUNK), 0);
}

// A run that mapped nothing hands write_all a 0 x 0 grid: refused, with a
// message, before anything is written (it left a comment and a header).
TEST_P(MapIo, WriteAllOfAnEmptyGridWritesNothing) {
  const std::string file = path("empty");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  float *no_rows[1] = {nullptr};
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_write_all(fp, no_rows, 0, 0, 0.1, "log.clf", "empty", "o", "d", nullptr, 0, nullptr, 0,
                                 nullptr, 0),
            -1);
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find("carmen_map_write_all"), std::string::npos) << said;
  EXPECT_NE(said.find("invalid map size 0 x 0"), std::string::npos) << said;
  ASSERT_EQ(carmen_fclose(fp), 0);
  if (GetParam() == std::string(".map")) EXPECT_EQ(read_bytes(file), "");
}

TEST_P(MapIo, CommentBlockIsCarmenReadable) {
  const std::string file = path("comments");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_comment_chunk(fp, 300, 200, 0.1, "fr079.log", std::string(200, 'd').c_str()), 0);
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  const std::string text = std::string(GetParam()).size() > 4 ? maptest::gunzip_file(file) : read_bytes(file);
  // Every line starts with '#' and fits fgets(buf, 100) with its newline.
  size_t start = 0, lines = 0;
  bool size_line = false;
  while (start < text.size() && text[start] == '#') {
    const size_t nl = text.find('\n', start);
    ASSERT_NE(nl, std::string::npos);
    EXPECT_LE(nl - start + 1, 99u);
    size_line |= text.compare(start, nl - start, "# Map size      : 300 x 200") == 0;
    start = nl + 1;
    ++lines;
  }
  EXPECT_TRUE(size_line);
  EXPECT_GE(lines, 5u);
  EXPECT_EQ(text.substr(start), "CARMENMAPFILEv020");
  EXPECT_EQ(carmen_map_file(file.c_str()), 1);
}

TEST_P(MapIo, NamedChunks) {
  const std::string file = path("named");
  CGrid a(1, 2), b(2, 1);
  a.block = {0.25f, 0.5f};
  b.block = {0.75f, 1.0f};
  carmen_global_offset_t off = {1, 2, 3};
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_map_write_named_gridmap_chunk(fp, "first", a.rows.data(), 1, 2, 0.1), 0);
  ASSERT_EQ(carmen_map_write_named_gridmap_chunk(fp, "second", b.rows.data(), 2, 1, 0.2), 0);
  ASSERT_EQ(carmen_map_write_named_global_offset_chunk(fp, "origin", &off), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);

  carmen_map_t map;
  std::memset(&map, 0, sizeof map);
  ASSERT_EQ(carmen_map_read_named_gridmap_chunk(file.c_str(), "second", &map), 0);
  EXPECT_EQ(map.config.x_size, 2);
  EXPECT_EQ(map.map[1][0], 1.0f);
  EXPECT_STREQ(map.config.map_name, "second");  // the named reader sets the chunk name, as CARMEN's
  std::free(map.map);
  std::free(map.complete_map);
  std::free(map.config.map_name);
  // No unnamed gridmap: the unnamed reader takes the first gridmap, named or
  // not, as CARMEN's does (it used to fail here; CARMEN's maptool then showed
  // a 0 x 0 map).
  ASSERT_EQ(carmen_map_read_gridmap_chunk(file.c_str(), &map), 0);
  EXPECT_EQ(map.config.x_size, 1);
  EXPECT_EQ(map.config.y_size, 2);
  EXPECT_EQ(map.map[0][1], 0.5f);
  EXPECT_STREQ(map.config.map_name, file.c_str());
  std::free(map.map);
  std::free(map.complete_map);
  std::free(map.config.map_name);
  carmen_global_offset_t back;
  ASSERT_EQ(carmen_map_read_named_global_offset_chunk(file.c_str(), "origin", &back), 0);
  EXPECT_EQ(back.theta, 3.0);
  // chunk_exists masks the named flag, like CARMEN's advance.
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK), 10 + 6 + 12 + 8);
  EXPECT_EQ(carmen_map_named_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK, "second"), 10 + 7 + 12 + 8);
  EXPECT_EQ(carmen_map_named_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK, "third"), 0);

  carmen_FILE *in = carmen_fopen(file.c_str(), "r");
  ASSERT_NE(in, nullptr);
  ASSERT_EQ(carmen_map_advance_to_named_chunk(in, CARMEN_MAP_GRIDMAP_CHUNK, "second"), 0);
  // Positioned at the type byte, as CARMEN leaves it: the id (17) + the
  // first chunk (5 + 36).
  EXPECT_EQ(carmen_ftell(in), 17 + 41);
  EXPECT_EQ(carmen_fgetc(in), CARMEN_MAP_GRIDMAP_CHUNK | CARMEN_MAP_NAMED_CHUNK_FLAG);
  carmen_fclose(in);
}

TEST_P(MapIo, AdvanceToChunkStopsAtTheTypeByte) {
  // A gzip or plain copy of freiburg.map.
  const std::string file = path("fr");
  if (std::string(GetParam()).size() > 4) {
    maptest::gzip_to_file(file, read_bytes(map_fixture("freiburg.map")));
  } else {
    maptest::write_bytes(file, read_bytes(map_fixture("freiburg.map")));
  }
  carmen_FILE *fp = carmen_fopen(file.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_advance_to_chunk(fp, CARMEN_MAP_GRIDMAP_CHUNK), 0);
  EXPECT_EQ(carmen_fgetc(fp), CARMEN_MAP_GRIDMAP_CHUNK);  // CARMEN's readers take the type next
  unsigned char buf[4 + 10 + 8];
  ASSERT_EQ(carmen_fread(buf, 1, sizeof buf, fp), sizeof buf);
  const std::string s(reinterpret_cast<char *>(buf), sizeof buf);
  EXPECT_EQ(maptest::read_i32(s, 0), 360022);
  EXPECT_EQ(s.substr(4, 10), "GRIDMAP   ");
  EXPECT_EQ(maptest::read_i32(s, 14), 300);
  EXPECT_EQ(maptest::read_i32(s, 18), 300);
  ASSERT_EQ(carmen_map_advance_to_chunk(fp, CARMEN_MAP_CREATOR_CHUNK), 0);  // rescans from the start
  EXPECT_EQ(carmen_ftell(fp), 17);  // freiburg.map has no comments: the creator follows the id
  EXPECT_EQ(carmen_map_advance_to_chunk(fp, CARMEN_MAP_PLACES_CHUNK), -1);
  carmen_fclose(fp);
}


// ---- CARMEN's comment block, byte for byte ---------------------------------
std::string carmen_comment_block(const std::string &author, time_t t, int sx, int sy, double res,
                                 const std::string &origin, const std::string &desc) {
  const std::string rule(53, '#');
  char buf[512];
  std::snprintf(buf, sizeof buf, "# Resolution    : %.1f\n", res);
  return rule + "\n#\n# Carnegie Mellon Robot Toolkit (CARMEN) map file\n#\n# Map author    : " + author +
         "\n# Creation date : " + std::asctime(std::localtime(&t)) + "# Map size      : " + std::to_string(sx) +
         " x " + std::to_string(sy) + "\n" + buf + "# Origin        : " + origin +
         "\n# Description   : " + desc + "#\n" + rule + "\n";
}

TEST_P(MapIo, CommentBlockHasCarmensBytes) {
  const std::string file = path("carmen_comments");
  const time_t before = std::time(nullptr);
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_comment_chunk(fp, 300, 200, 0.05, "fr079.log", "a test map"), 0);
  ASSERT_EQ(carmen_map_write_comment_chunk(fp, 1, 2, 0.1, nullptr, nullptr), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  const time_t after = std::time(nullptr);
  const std::string text = std::string(GetParam()).size() > 4 ? maptest::gunzip_file(file) : read_bytes(file);
  // Each block reads the clock when it is written: the two may fall on either side of a second.
  bool matched = false;
  for (time_t t1 = before; t1 <= after && !matched; ++t1) {
    for (time_t t2 = t1; t2 <= after && !matched; ++t2) {
      matched = text == carmen_comment_block(login_or_unknown(), t1, 300, 200, 0.05, "fr079.log", "a test map") +
                            carmen_comment_block(login_or_unknown(), t2, 1, 2, 0.1, "(null)", "(null)");
    }
  }
  EXPECT_TRUE(matched) << text;
  // The Description line runs into the next line's '#', as in CARMEN's files.
  EXPECT_NE(text.find("# Description   : a test map#\n"), std::string::npos);
}

TEST_P(MapIo, CreatorUserIsTheLoginName) {
  const std::string file = path("creator_user");
  CGrid g(1, 1);
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  ASSERT_EQ(carmen_map_write_id(fp), 0);
  ASSERT_EQ(carmen_map_write_creator_chunk(fp, "o", "d"), 0);
  ASSERT_EQ(carmen_fclose(fp), 0);
  char user[11];
  ASSERT_EQ(carmen_map_read_creator_chunk(file.c_str(), nullptr, user, nullptr, nullptr), 0);
  std::string want = login_or_unknown().substr(0, 10);
  while (!want.empty() && want.back() == ' ') want.pop_back();
  EXPECT_EQ(std::string(user), want);
}


// ---- CARMEN's map-server calls, without IPC ---------------------------------
TEST(MapIoServer, StandInsLinkAndSayThereIsNoIpc) {
  carmen_map_publish_update();  // nothing to publish to: a no-op
  carmen_map_set_filename(nullptr);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_initialize_ipc(), -1);
  std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("no IPC in vasco_gpu"), std::string::npos) << err;
  // The stored name is the one a publish would use; the message names it.
  carmen_map_set_filename("first.map");
  carmen_map_set_filename("maps/level2.map");
  testing::internal::CaptureStderr();
  carmen_map_publish_update();
  EXPECT_EQ(carmen_map_initialize_ipc(), -1);
  err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("maps/level2.map"), std::string::npos) << err;
  EXPECT_EQ(err.find("first.map"), std::string::npos) << err;
  carmen_map_set_filename(nullptr);
}


INSTANTIATE_TEST_SUITE_P(PlainAndGzip, MapIo, ::testing::Values(".map", ".map.gz"), plain_or_gzip);

TEST(MapIoFreiburg, ReadersAndUtilities) {
  const std::string file = map_fixture("freiburg.map");
  EXPECT_EQ(carmen_map_file(file.c_str()), 1);
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK), 360022);
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_CREATOR_CHUNK), 184);
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_PLACES_CHUNK), 0);
  carmen_map_config_t config;
  ASSERT_EQ(carmen_map_read_gridmap_config(file.c_str(), &config), 0);
  EXPECT_EQ(config.x_size, 300);
  EXPECT_EQ(config.y_size, 300);
  EXPECT_EQ(config.resolution, double(0.1f));
  EXPECT_STREQ(config.map_name, file.c_str());
  std::free(config.map_name);
  time_t when = 0;
  char user[11];
  ASSERT_EQ(carmen_map_read_creator_chunk(file.c_str(), &when, user, nullptr, nullptr), 0);
  EXPECT_STREQ(user, "nickr");
  EXPECT_GT(when, 1000000000);  // 2001-09-09: the map is from 2002
  EXPECT_LT(when, 1100000000);  // 2004-11-09
  // A missing places chunk: -1 and an empty list, silently, as CARMEN's
  // reader (maptool asks for places on every map; this used to print a line).
  carmen_map_placelist_t plist;
  std::memset(&plist, 0x5a, sizeof plist);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_places_chunk(file.c_str(), &plist), -1);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(plist.places, nullptr);
  EXPECT_EQ(plist.num_places, 0);
  // A missing laser scan chunk is reported, as CARMEN reports it.
  carmen_laser_scan_p scans = nullptr;
  int nscans = 7;
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_laserscans_chunk(file.c_str(), &scans, &nscans), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find(file), std::string::npos) << err;
  EXPECT_NE(err.find("LASERSCANS"), std::string::npos) << err;
  EXPECT_EQ(nscans, 0);
}

TEST(MapIoWriters, RejectBadArguments) {
  TempDir dir;
  const std::string file = dir.file("bad.map");
  carmen_FILE *fp = carmen_fopen(file.c_str(), "w");
  ASSERT_NE(fp, nullptr);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_write_gridmap_chunk(fp, nullptr, 3, 3, 0.1), -1);
  CGrid g(2, 2);
  EXPECT_EQ(carmen_map_write_gridmap_chunk(fp, g.rows.data(), 0, 2, 0.1), -1);
  carmen_offlimits_t bad = {17, 0, 0, 0, 0};
  EXPECT_EQ(carmen_map_write_offlimits_chunk(fp, &bad, 1), -1);
  carmen_place_t place;
  std::memset(&place, 0, sizeof place);
  place.type = 7;  // CARMEN knows 0, 1 and 2
  EXPECT_EQ(carmen_map_write_places_chunk(fp, &place, 1), -1);
  EXPECT_EQ(carmen_map_write_id(nullptr), -1);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("carmen_map_write_offlimits_chunk"), std::string::npos) << err;
  carmen_fclose(fp);
  EXPECT_EQ(read_bytes(file), "");  // nothing half-written
}

}  // namespace
