// What the map file tests share: a sample map using every chunk type, a
// field-by-field comparison of two maps, and readers that expect a refusal
// or collect the warnings.
#ifndef VASCO_TESTS_MAP_FILE_TEST_SUPPORT_H
#define VASCO_TESTS_MAP_FILE_TEST_SUPPORT_H

#include <gtest/gtest.h>

#include <exception>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/map_file.h"
#include "map_test_support.h"

namespace mapfiletest {

using namespace maptest;
using carmen::FileError;
using carmen::MapFile;

// Expects read_map_file(path) to throw a FileError whose text names the file
// and contains every one of `parts`.
inline void expect_rejected(const std::string &path, const std::vector<std::string> &parts,
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
inline MapFile sample_map() {
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

inline void expect_same_map(const MapFile &a, const MapFile &b) {
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

// Reads `path` collecting the warnings.
inline MapFile read_warned(const std::string &path, std::vector<std::string> *warnings,
                           carmen::MapReadOptions opts = {}) {
  opts.on_warning = [warnings](const std::string &w) { warnings->push_back(w); };
  return carmen::read_map_file(path, opts);
}

inline void write_plain_or_gzip(const std::string &path, const std::string &bytes) {
  if (path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0) {
    gzip_to_file(path, bytes);
  } else {
    write_bytes(path, bytes);
  }
}

}  // namespace mapfiletest

#endif  // VASCO_TESTS_MAP_FILE_TEST_SUPPORT_H
