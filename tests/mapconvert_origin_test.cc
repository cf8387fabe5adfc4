// A map's origin through mapconvert keeps its double: a .map's OFFSET at a
// UTM northing (5.4e6 m, where a float is off by up to 0.25 m) comes out as
// the map_server YAML's origin (.pgm, .png+yaml, .yaml) with the same
// doubles, and back into a .map's OFFSET.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "carmen_compat/map_format.h"
#include "map_test_support.h"
#include "tool_support.h"

namespace {

using maptest::TempDir;

// The origin's text as a person would give it, and its doubles by strtod:
// the route the comparison takes is not the writer's.
const char *const kX = "500000.123456789";
const char *const kY = "5400000.987654321";
const char *const kTheta = "0.123456789012345";

carmen::GlobalOffset utm_origin() {
  return {std::strtod(kX, nullptr), std::strtod(kY, nullptr), std::strtod(kTheta, nullptr)};
}

std::string write_utm_map(const TempDir &dir) {
  carmen::MapToWrite w;
  w.grid = carmen::GridMap::filled(30, 20, 0.05, 0.25f);
  w.grid.at(3, 4) = 0.9f;
  w.origin = utm_origin();
  const std::string path = dir.file("utm.map");
  carmen::write_map(path, w);
  return path;
}

// The three numbers of the YAML's "origin: [x, y, theta]" line, by strtod.
std::vector<double> yaml_origin_by_strtod(const std::string &yaml) {
  std::ifstream in(yaml);
  std::vector<double> xyz;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("origin: [", 0) != 0) continue;
    std::istringstream parts(line.substr(9, line.find(']') - 9));
    for (std::string part; std::getline(parts, part, ',');) xyz.push_back(std::strtod(part.c_str(), nullptr));
  }
  return xyz;
}

void expect_utm_origin(const carmen::GlobalOffset &o, const std::string &what) {
  const carmen::GlobalOffset want = utm_origin();
  EXPECT_EQ(o.x, want.x) << what;  // exactly: not within a float's rounding
  EXPECT_EQ(o.y, want.y) << what;
  EXPECT_EQ(o.theta, want.theta) << what;
}

TEST(MapconvertOrigin, AUtmOffsetKeepsItsDoublesInTheYaml) {
  TempDir dir;
  const std::string map = write_utm_map(dir);
  ASSERT_TRUE(carmen::read_map(map).origin.has_value());
  expect_utm_origin(*carmen::read_map(map).origin, "the .map written");
  struct Case {
    std::string out, yaml;
  };
  for (const Case &c : {Case{"a.pgm", "a.yaml"}, Case{"b.png+yaml", "b.yaml"}, Case{"c.yaml", "c.yaml"}}) {
    const tooltest::ToolRun r = tooltest::run_tool("mapconvert", {"-q", map, dir.file(c.out)});
    ASSERT_EQ(r.status, 0) << c.out << ": " << r.output;
    const std::vector<double> text = yaml_origin_by_strtod(dir.file(c.yaml));
    ASSERT_EQ(text.size(), 3u) << c.yaml;
    expect_utm_origin({text[0], text[1], text[2]}, c.yaml + "'s text");
    const carmen::MapRead back = carmen::read_map(dir.file(c.yaml));
    ASSERT_TRUE(back.origin.has_value()) << c.yaml;
    expect_utm_origin(*back.origin, c.yaml + " read back");
  }
  // And back: the YAML's origin becomes the new .map's OFFSET, unchanged.
  const tooltest::ToolRun r = tooltest::run_tool("mapconvert", {"-q", dir.file("a.yaml"), dir.file("again.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  const carmen::MapRead again = carmen::read_map(dir.file("again.map"));
  ASSERT_TRUE(again.origin.has_value());
  expect_utm_origin(*again.origin, "again.map");
}

}  // namespace
