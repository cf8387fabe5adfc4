// carmen/map_io.h: CARMEN's C readers on maps that are odd or damaged: named
// chunks taken by the unnamed readers, failed reads leaving outputs zeroed,
// damage after the chunk asked for, a GRIDMAP chunk cut short, OFFLIMITS
// chunks in CARMEN's writers' layouts, CARMEN's damaged maps.
#include "carmen/map_io.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "map_io_test_support.h"

namespace {

using namespace mapiotest;

// ---- Named chunks read by the unnamed readers (issue 23) -------------------
// A map whose only GRIDMAP and PLACES chunks are named, built byte by byte:
// CARMEN's unnamed readers take the first chunk of the type, named or not.
std::string named_only_map(std::vector<float> *cells_out) {
  std::vector<float> cells(100 * 120);
  for (size_t i = 0; i < cells.size(); ++i) cells[i] = (i % 7 == 0) ? -1.0f : float(i % 100) / 100.0f;
  std::string grid = i32(100) + i32(120) + f32(0.05f);
  for (float v : cells) grid += f32(v);
  auto place = [](int type, const std::string &name, std::vector<float> v) {
    std::string b = i32(type) + maptest::field(name, 20, '\0');
    for (float f : v) b += f32(f);
    return b;
  };
  const std::string places = i32(3) + place(CARMEN_NAMED_POSITION_TYPE, "door", {1, 2}) +
                             place(CARMEN_NAMED_POSE_TYPE, "desk", {3, 4, 0.5f}) +
                             place(CARMEN_LOCALIZATION_INIT_TYPE, "start", {5, 6, 1, 0.25f, 0.5f, 0.125f});
  if (cells_out != nullptr) *cells_out = cells;
  return "# named chunks only\n" + kId + chunk(CARMEN_MAP_GRIDMAP_CHUNK, "GRIDMAP", grid, "level1", true) +
         chunk(CARMEN_MAP_PLACES_CHUNK, "PLACES", places, "level1", true);
}

TEST_P(MapIo, UnnamedReadersTakeTheFirstChunkNamedOrNot) {
  const std::string file = path("named_only");
  std::vector<float> cells;
  const std::string bytes = named_only_map(&cells);
  if (std::string(GetParam()).size() > 4) {
    maptest::gzip_to_file(file, bytes);
  } else {
    maptest::write_bytes(file, bytes);
  }
  carmen_map_config_t config;
  ASSERT_EQ(carmen_map_read_gridmap_config(file.c_str(), &config), 0);
  EXPECT_EQ(config.x_size, 100);
  EXPECT_EQ(config.y_size, 120);
  EXPECT_EQ(config.resolution, double(0.05f));
  EXPECT_STREQ(config.map_name, file.c_str());
  std::free(config.map_name);

  carmen_map_t map;
  ASSERT_EQ(carmen_map_read_gridmap_chunk(file.c_str(), &map), 0);
  EXPECT_EQ(map.config.x_size, 100);
  EXPECT_EQ(map.config.y_size, 120);
  EXPECT_EQ(0, std::memcmp(map.complete_map, cells.data(), cells.size() * sizeof(float)));
  EXPECT_EQ(map.map[99][119], cells[99 * 120 + 119]);
  std::free(map.map);
  std::free(map.complete_map);
  std::free(map.config.map_name);

  carmen_map_placelist_t places;
  ASSERT_EQ(carmen_map_read_places_chunk(file.c_str(), &places), 0);
  ASSERT_EQ(places.num_places, 3);
  EXPECT_STREQ(places.places[0].name, "door");
  EXPECT_EQ(places.places[1].theta, 0.5);
  EXPECT_EQ(places.places[2].type, CARMEN_LOCALIZATION_INIT_TYPE);
  EXPECT_EQ(places.places[2].theta_std, 0.125);
  // What maptool add_place does next: realloc() the list.
  places.places = static_cast<carmen_place_p>(std::realloc(places.places, 4 * sizeof(carmen_place_t)));
  ASSERT_NE(places.places, nullptr);
  std::free(places.places);

  // chunk_exists: 10 + "level1\0" + 12 + 4 * 12000.
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK), 10 + 7 + 12 + 4 * 12000);
  EXPECT_EQ(carmen_map_named_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK, "level1"),
            10 + 7 + 12 + 4 * 12000);
  EXPECT_EQ(carmen_map_named_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK, "level2"), 0);
}

// Every reader clears its outputs before it can fail, so that a caller that
// free()s or realloc()s them afterwards (CARMEN's maptool) does not crash.
TEST_P(MapIo, FailedReadsLeaveOutputsZeroed) {
  const std::string missing = path("does_not_exist");
  const std::string empty = path("empty_map");  // a map with no chunks at all
  if (std::string(GetParam()).size() > 4) {
    maptest::gzip_to_file(empty, kId);
  } else {
    maptest::write_bytes(empty, kId);
  }
  for (const std::string &file : {missing, empty}) {
    testing::internal::CaptureStderr();
    carmen_map_t map;
    std::memset(&map, 0x5a, sizeof map);
    EXPECT_EQ(carmen_map_read_gridmap_chunk(file.c_str(), &map), -1);
    EXPECT_EQ(map.config.x_size, 0);
    EXPECT_EQ(map.config.y_size, 0);
    EXPECT_EQ(map.config.resolution, 0.0);
    EXPECT_EQ(map.config.map_name, nullptr);
    EXPECT_EQ(map.complete_map, nullptr);
    EXPECT_EQ(map.map, nullptr);
    std::memset(&map, 0x5a, sizeof map);
    EXPECT_EQ(carmen_map_read_named_gridmap_chunk(file.c_str(), "x", &map), -1);
    EXPECT_EQ(map.config.map_name, nullptr);
    EXPECT_EQ(map.map, nullptr);

    carmen_map_config_t config;
    std::memset(&config, 0x5a, sizeof config);
    EXPECT_EQ(carmen_map_read_gridmap_config(file.c_str(), &config), -1);
    EXPECT_EQ(config.x_size, 0);
    EXPECT_EQ(config.y_size, 0);
    EXPECT_EQ(config.map_name, nullptr);

    carmen_map_placelist_t places;
    std::memset(&places, 0x5a, sizeof places);
    EXPECT_EQ(carmen_map_read_places_chunk(file.c_str(), &places), -1);
    EXPECT_EQ(places.places, nullptr);
    EXPECT_EQ(places.num_places, 0);

    carmen_offlimits_p offl;
    int n;
    std::memset(&offl, 0x5a, sizeof offl);
    n = 0x5a5a;
    EXPECT_EQ(carmen_map_read_offlimits_chunk(file.c_str(), &offl, &n), -1);
    EXPECT_EQ(offl, nullptr);
    EXPECT_EQ(n, 0);

    carmen_laser_scan_p scans;
    std::memset(&scans, 0x5a, sizeof scans);
    n = 0x5a5a;
    EXPECT_EQ(carmen_map_read_laserscans_chunk(file.c_str(), &scans, &n), -1);
    EXPECT_EQ(scans, nullptr);
    EXPECT_EQ(n, 0);

    carmen_global_offset_t off = {1, 2, 3};
    EXPECT_EQ(carmen_map_read_global_offset_chunk(file.c_str(), &off), -1);
    EXPECT_EQ(off.x, 0.0);
    EXPECT_EQ(off.theta, 0.0);

    time_t when = 12345;
    char user[11] = "xxxxxxxxxx", origin[81] = "yyy", desc[81] = "zzz";
    EXPECT_EQ(carmen_map_read_creator_chunk(file.c_str(), &when, user, origin, desc), -1);
    EXPECT_EQ(when, 0);
    EXPECT_STREQ(user, "");
    EXPECT_STREQ(origin, "");
    EXPECT_STREQ(desc, "");

    carmen_hmap_t hmap;
    std::memset(&hmap, 0x5a, sizeof hmap);
    EXPECT_EQ(carmen_map_read_hmap_chunk(file.c_str(), &hmap), -1);
    EXPECT_EQ(hmap.num_zones, 0);
    EXPECT_EQ(hmap.zone_names, nullptr);
    EXPECT_EQ(hmap.num_links, 0);
    EXPECT_EQ(hmap.links, nullptr);
    testing::internal::GetCapturedStderr();
  }
}


// ---- A damaged chunk after the one asked for --------------------------------
// thickwean: an intact 477 x 170 GRIDMAP at byte 563, then at byte 324950 a
// chunk whose header claims 1.3 GB with 230 bytes left. Read plain and gzip.
TEST_P(MapIo, DamageAfterTheChunkDoesNotMatterDamageBeforeIsReported) {
  const std::string file = path("thickwean");
  const std::string raw = maptest::gunzip_file(map_fixture("damaged/thickwean.map.gz"));
  ASSERT_EQ(raw.size(), 325185u);
  if (std::string(GetParam()).size() > 4) {
    maptest::gzip_to_file(file, raw);
  } else {
    maptest::write_bytes(file, raw);
  }
  carmen_map_config_t config;
  ASSERT_EQ(carmen_map_read_gridmap_config(file.c_str(), &config), 0);
  EXPECT_EQ(config.x_size, 477);
  EXPECT_EQ(config.y_size, 170);
  std::free(config.map_name);
  carmen_map_t map;
  testing::internal::CaptureStderr();  // its cells hold some garbage: a warning
  ASSERT_EQ(carmen_map_read_gridmap_chunk(file.c_str(), &map), 0);
  testing::internal::GetCapturedStderr();
  EXPECT_EQ(map.config.x_size, 477);
  EXPECT_EQ(map.config.y_size, 170);
  EXPECT_EQ(map.map[0][0], maptest::read_f32(raw, 563 + 27));
  std::free(map.map);
  std::free(map.complete_map);
  std::free(map.config.map_name);
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK), 324382);
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_CREATOR_CHUNK), 184);
  // PLACES would lie after the damaged chunk: the scan reaches the damage,
  // and the message names it and its offset.
  carmen_map_placelist_t places;
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_read_places_chunk(file.c_str(), &places), -1);
  std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find(file), std::string::npos) << err;
  EXPECT_NE(err.find("at byte 324950"), std::string::npos) << err;
  EXPECT_EQ(places.places, nullptr);
  EXPECT_EQ(places.num_places, 0);
  testing::internal::CaptureStderr();
  EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_PLACES_CHUNK), 0);
  err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("at byte 324950"), std::string::npos) << err;
}

// ---- A GRIDMAP chunk cut short ------------------------------------------------
// CARMEN's reader renders a gridmap whose file ends inside its cells (the
// bytes there read, the rest as calloc() left them: zeros); so does ours,
// with a warning naming the chunk and the bytes missing. The other readers
// pass it silently.
TEST_P(MapIo, GridmapCutShortIsReadAsCarmenReadsIt) {
  const std::string file = path("short");
  std::string cells;
  for (float v : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f, 0.125f}) cells += f32(v);
  const std::string grid = chunk(1, "GRIDMAP", i32(3) + i32(2) + f32(0.5f) + cells);
  const std::string named = chunk(1, "GRIDMAP", i32(3) + i32(2) + f32(0.5f) + cells, "upstairs", true);
  for (const std::string &whole : {grid, named}) {
    const bool is_named = whole[0] != '\x01';
    // Five bytes short: the last cell gone, the one before it cut.
    const std::string bytes = kId + whole.substr(0, whole.size() - 5);
    if (std::string(GetParam()).size() > 4) {
      maptest::gzip_to_file(file, bytes);
    } else {
      maptest::write_bytes(file, bytes);
    }
    carmen_map_t map;
    std::memset(&map, 0x5a, sizeof map);
    testing::internal::CaptureStderr();
    const int rc = is_named ? carmen_map_read_named_gridmap_chunk(file.c_str(), "upstairs", &map)
                            : carmen_map_read_gridmap_chunk(file.c_str(), &map);
    std::string err = testing::internal::GetCapturedStderr();
    ASSERT_EQ(rc, 0) << err;
    const std::string fn = is_named ? "carmen_map_read_named_gridmap_chunk" : "carmen_map_read_gridmap_chunk";
    EXPECT_EQ(err, fn + ": " + file + ": warning: the GRIDMAP chunk at byte 17 " +
                       (is_named ? "(named \"upstairs\") " : "") + "is 5 bytes short: it claims " +
                       std::to_string(maptest::read_i32(whole, 1)) + " bytes but the file ends after " +
                       std::to_string(maptest::read_i32(whole, 1) - 5) +
                       " of them; its last 2 of 6 cells (x-major order) are missing and read as CARMEN's "
                       "reader leaves them: zero bytes (0, free), the first after the bytes that came\n");
    EXPECT_EQ(map.config.x_size, 3);
    EXPECT_EQ(map.config.y_size, 2);
    EXPECT_EQ(map.map[0][0], 0.0f);
    EXPECT_EQ(map.map[1][1], 0.75f);
    EXPECT_EQ(map.map[2][0], maptest::cells_cut_short(f32(1.0f), 3)[0]);  // 1.0f's 3 low bytes and a zero
    EXPECT_EQ(map.map[2][1], 0.0f);
    std::free(map.map);
    std::free(map.complete_map);
    std::free(map.config.map_name);
    // The config and the chunk's size, as stored; the readers of other
    // chunks pass it without a word.
    testing::internal::CaptureStderr();
    carmen_map_config_t config;
    EXPECT_EQ(carmen_map_read_gridmap_config(file.c_str(), &config), 0);
    EXPECT_EQ(config.x_size, 3);
    std::free(config.map_name);
    EXPECT_EQ(carmen_map_chunk_exists(file.c_str(), CARMEN_MAP_GRIDMAP_CHUNK), maptest::read_i32(whole, 1));
    carmen_offlimits_p list = nullptr;
    int n = 0;
    EXPECT_EQ(carmen_map_read_offlimits_chunk(file.c_str(), &list, &n), -1);
    carmen_map_placelist_t places;
    EXPECT_EQ(carmen_map_read_places_chunk(file.c_str(), &places), -1);
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  }
}

// ---- OFFLIMITS chunks as CARMEN's writers write them --------------------------
// CARMEN's line loop leaves out a line (its size still counts it), its named
// writer's size field says 22: read as the layout CARMEN wrote, with a
// warning, and the chunks after them found where they are.
TEST_P(MapIo, OfflimitsInCarmensLayoutsAreRead) {
  const std::string file = path("carmen_offlimits");
  const std::vector<maptest::CarmenOffItem> items = {
      {0, 1, 2, 0, 0}, {1, 0, 0, 5, 5}, {2, 1, 1, 2, 2}, {1, 3, 4, 7, 8}};
  const std::string grid = chunk(1, "GRIDMAP", i32(1) + i32(1) + f32(1) + f32(0.5f));
  const std::string scans = chunk(16, "LASERSCANS", i32(1) + f32(1) + f32(2) + f32(3) + i32(1) + f32(4));
  const std::string bytes = kId + grid + maptest::carmen_offlimits_chunk(items) +
                            maptest::carmen_offlimits_chunk(items, "zone", true) + scans;
  if (std::string(GetParam()).size() > 4) {
    maptest::gzip_to_file(file, bytes);
  } else {
    maptest::write_bytes(file, bytes);
  }
  for (const char *name : {static_cast<const char *>(nullptr), "zone"}) {
    carmen_offlimits_p list = nullptr;
    int n = 0;
    testing::internal::CaptureStderr();
    const int rc = name ? carmen_map_read_named_offlimits_chunk(file.c_str(), name, &list, &n)
                        : carmen_map_read_offlimits_chunk(file.c_str(), &list, &n);
    const std::string err = testing::internal::GetCapturedStderr();
    ASSERT_EQ(rc, 0) << err;
    const std::string at = name ? "at byte 115 (named \"zone\")" : "at byte 48";
    const std::string fn = name ? "carmen_map_read_named_offlimits_chunk" : "carmen_map_read_offlimits_chunk";
    EXPECT_EQ(err.rfind(fn + ": " + file + ": warning: the OFFLIMITS chunk " + at, 0), 0u) << err;
    EXPECT_NE(err.find("1 of its 2 lines were counted but never written"), std::string::npos) << err;
    ASSERT_EQ(n, 3);  // the point, the line written, the rectangle
    EXPECT_EQ(list[0].type, CARMEN_OFFLIMITS_POINT_ID);
    EXPECT_EQ(list[0].y1, 2);
    EXPECT_EQ(list[1].type, CARMEN_OFFLIMITS_LINE_ID);
    EXPECT_EQ(list[1].x2, 5);
    EXPECT_EQ(list[2].type, CARMEN_OFFLIMITS_RECT_ID);
    EXPECT_EQ(list[2].y2, 2);
    std::free(list);
  }
  carmen_laser_scan_p scan_list = nullptr;
  int num = 0;
  ASSERT_EQ(carmen_map_read_laserscans_chunk(file.c_str(), &scan_list, &num), 0);
  ASSERT_EQ(num, 1);
  EXPECT_EQ(scan_list[0].range[0], 4.0f);
  std::free(scan_list[0].range);
  std::free(scan_list);
}

INSTANTIATE_TEST_SUITE_P(PlainAndGzip, MapIo, ::testing::Values(".map", ".map.gz"), plain_or_gzip);

// The damaged maps are read as CARMEN reads them: each chunk from a scan of
// the headers up to it, so damage after it does not matter (these readers
// used to check the whole file and failed on all four). What is damaged is
// reported with its byte offset; what is not there is never allocated.
TEST(MapIoDamaged, IntactChunksAreReadAndDamageIsReported) {
  struct Case {
    const char *name;
    int grid_rc;  // carmen_map_read_gridmap_chunk
    int config_rc, sx, sy;
    int creator_rc;
    const char *grid_message;  // on stderr from the gridmap reader
  };
  const Case cases[] = {
      // Garbage cells in an intact chunk: returned as stored, with a warning.
      {"longwood", 0, 0, 536, 379, 0, "GRIDMAP chunk at byte 584 holds 39919 invalid cell values"},
      // The gridmap chunk lacks a byte: read as CARMEN reads it, its last
      // byte a zero, with a warning; the cells after the lost byte are
      // shifted (garbage): returned as stored, with the other warning.
      {"nsh_level_3", 0, 0, 677, 469, 0,
       "GRIDMAP chunk at byte 540 is 1 byte short: it claims 1270074 bytes but the file ends after 1270073"},
      // A damaged chunk after an intact gridmap (with some damaged cells).
      {"thickwean", 0, 0, 477, 170, 0, "GRIDMAP chunk at byte 563 holds 7656 invalid cell values"},
      // gzip inside gzip: no map at all.
      {"wean5300", -1, -1, 0, 0, -1, "compressed twice"},
  };
  for (const Case &c : cases) {
    const std::string file = map_fixture(std::string("damaged/") + c.name + ".map.gz");
    carmen_map_t map;
    std::memset(&map, 0x5a, sizeof map);  // as uninitialised: the readers clear it
    carmen_map_config_t config;
    std::memset(&config, 0x5a, sizeof config);
    testing::internal::CaptureStderr();
    EXPECT_EQ(carmen_map_read_gridmap_chunk(file.c_str(), &map), c.grid_rc) << c.name;
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find(file), std::string::npos) << err;
    EXPECT_NE(err.find(c.grid_message), std::string::npos) << c.name << ": " << err;
    testing::internal::CaptureStderr();
    EXPECT_EQ(carmen_map_read_gridmap_config(file.c_str(), &config), c.config_rc) << c.name;
    EXPECT_EQ(carmen_map_read_creator_chunk(file.c_str(), nullptr, nullptr, nullptr, nullptr), c.creator_rc)
        << c.name;
    testing::internal::GetCapturedStderr();
    EXPECT_EQ(config.x_size, c.sx) << c.name;
    EXPECT_EQ(config.y_size, c.sy) << c.name;
    if (c.config_rc == 0) {
      EXPECT_EQ(config.resolution, double(0.1f));
      EXPECT_STREQ(config.map_name, file.c_str());
    } else {
      EXPECT_EQ(config.map_name, nullptr);
    }
    std::free(config.map_name);
    if (c.grid_rc == 0) {
      EXPECT_EQ(map.config.x_size, c.sx);
      EXPECT_EQ(map.config.y_size, c.sy);
      ASSERT_NE(map.map, nullptr);
      EXPECT_EQ(map.map[1], map.complete_map + c.sy);
    } else {  // cleared, so that free() of it is safe
      EXPECT_EQ(map.config.x_size, 0);
      EXPECT_EQ(map.config.y_size, 0);
      EXPECT_EQ(map.config.map_name, nullptr);
      EXPECT_EQ(map.complete_map, nullptr);
      EXPECT_EQ(map.map, nullptr);
    }
    std::free(map.map);
    std::free(map.complete_map);
    std::free(map.config.map_name);
  }
  // wean5300 is not a map (its data is gzip inside gzip); the others are,
  // by their id.
  EXPECT_EQ(carmen_map_file(map_fixture("damaged/wean5300.map.gz").c_str()), 0);
  EXPECT_EQ(carmen_map_file(map_fixture("damaged/longwood.map.gz").c_str()), 1);
  EXPECT_EQ(carmen_map_file("/nonexistent/file.map"), 0);
}

}  // namespace
