// The mapdiff tool, run as a program, and the grid comparison behind it.
#include <gtest/gtest.h>
#include <png.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "carmen_compat/map_format.h"
#include "map_test_support.h"
#include "tool_support.h"
#include "carmen_compat/map_compare.h"

namespace {

using carmen::GlobalOffset;
using carmen::GridMap;
using maptest::TempDir;
using tooltest::contains;
using tooltest::ToolRun;

ToolRun mapdiff(const std::vector<std::string> &args) { return tooltest::run_tool("mapdiff", args); }

void write_grid(const std::string &path, const GridMap &g, std::optional<GlobalOffset> offset = std::nullopt) {
  carmen::MapFile m;
  m.gridmap = g;
  m.offset = offset;
  carmen::write_map_file(path, m);
}

// 6 x 4 cells at 0.1 m: free 0.125 everywhere but an unknown corner (0, 0),
// an occupied (5, 3) and a 0.75 at (2, 1).
GridMap base_grid() {
  GridMap g = GridMap::filled(6, 4, 0.1, 0.125f);
  g.at(0, 0) = carmen::kUnknownCell;
  g.at(5, 3) = 1.0f;
  g.at(2, 1) = 0.75f;
  return g;
}

// A window of `g`: size_x x size_y cells starting at its cell (x0, y0).
GridMap crop(const GridMap &g, int x0, int y0, int size_x, int size_y) {
  GridMap c = GridMap::filled(size_x, size_y, g.resolution);
  for (int x = 0; x < size_x; ++x)
    for (int y = 0; y < size_y; ++y) c.at(x, y) = g.at(x0 + x, y0 + y);
  return c;
}

// An RGB PNG read back with libpng's simplified API (not mapdiff's code).
struct RgbImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  const uint8_t *pixel(int col, int row) const { return &rgb[(size_t(row) * size_t(width) + size_t(col)) * 3]; }
};

bool read_png_rgb(const std::string &path, RgbImage *out) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return false;
  image.format = PNG_FORMAT_RGB;
  out->rgb.resize(PNG_IMAGE_SIZE(image));
  out->width = int(image.width);
  out->height = int(image.height);
  const bool ok = png_image_finish_read(&image, nullptr, out->rgb.data(), 0, nullptr) != 0;
  png_image_free(&image);
  return ok;
}

class MapDiff : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!maptest::file_exists(std::string(VASCO_BIN_DIR) + "/mapdiff"))
      GTEST_SKIP() << "mapdiff is not built in " << VASCO_BIN_DIR;
    a_ = dir_.file("a.map");
    write_grid(a_, base_grid());
  }
  // Writes B = the base grid changed by `edit`, returns its path.
  template <class Edit>
  std::string write_b(Edit edit, const std::string &name = "b.map") {
    GridMap g = base_grid();
    edit(g);
    write_grid(dir_.file(name), g);
    return dir_.file(name);
  }
  TempDir dir_;
  std::string a_;
};

TEST_F(MapDiff, Usage) {
  const ToolRun help = mapdiff({"--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_TRUE(contains(help.output, "Usage:")) << help.output;
  EXPECT_TRUE(contains(help.output, "--tolerance")) << help.output;
  EXPECT_EQ(mapdiff({}).status, 2);
  EXPECT_EQ(mapdiff({a_}).status, 2);
  EXPECT_EQ(mapdiff({a_, a_, a_}).status, 2);
  const ToolRun bogus = mapdiff({"--bogus", a_, a_});
  EXPECT_EQ(bogus.status, 2);
  EXPECT_TRUE(contains(bogus.output, "--bogus")) << bogus.output;
  EXPECT_EQ(mapdiff({"--top", "-1", a_, a_}).status, 2);
  EXPECT_EQ(mapdiff({"--tolerance", "x", a_, a_}).status, 2);
  EXPECT_EQ(mapdiff({"--min-class-agreement", "1.5", a_, a_}).status, 2);
  EXPECT_EQ(mapdiff({"--quiet", "--json", a_, a_}).status, 2);
  EXPECT_EQ(mapdiff({"--png", a_, a_, a_}).status, 2);  // would overwrite A
}

TEST_F(MapDiff, IdenticalMaps) {
  // The same grid, once gzipped: the files differ, the GRIDMAPs do not.
  write_grid(dir_.file("b.map.gz"), base_grid());
  const ToolRun r = mapdiff({a_, dir_.file("b.map.gz")});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "identical: yes")) << r.output;
  EXPECT_TRUE(contains(r.output, "size 6 x 4 cells, resolution 0.100000001 m, offset none")) << r.output;
  EXPECT_TRUE(contains(r.output, "verdict: identical\n")) << r.output;
  const ToolRun quiet = mapdiff({"--quiet", a_, dir_.file("b.map.gz")});
  EXPECT_EQ(quiet.status, 0);
  EXPECT_EQ(quiet.output, "identical\n");
  // A map without an OFFSET chunk says nothing about where it lies: still identical.
  write_grid(dir_.file("moved.map"), base_grid(), GlobalOffset{1, 2, 0});
  const ToolRun moved = mapdiff({a_, dir_.file("moved.map")});
  EXPECT_EQ(moved.status, 0) << moved.output;
  EXPECT_TRUE(contains(moved.output, "offset x 1 y 2 theta 0\n")) << moved.output;
  EXPECT_TRUE(contains(moved.output, "note: the OFFSET chunks differ\n")) << moved.output;
}

// "-" reads a map (uncompressed: a map's reader goes by the name's .gz) from
// standard input; both A and B "-" is a usage error.
TEST_F(MapDiff, DashIsStandardInput) {
  write_grid(dir_.file("b.map"), base_grid());
  const std::string out = dir_.file("out.txt");
  EXPECT_EQ(tooltest::run_tool_piped(dir_.file("b.map"), "mapdiff", {"-q", a_, "-"}, out), 0);
  EXPECT_EQ(maptest::read_bytes(out), "identical\n");
  const std::string b = write_b([](GridMap &g) { g.at(0, 0) = 0.9f; });
  EXPECT_EQ(tooltest::run_tool_piped(b, "mapdiff", {"-q", "-", a_}, out), 1);
  EXPECT_EQ(tooltest::run_tool_piped(a_, "mapdiff", {"-", "-"}, out), 2);
}

// The same GRIDMAP 1.9e8 m away is another map, unless --no-offset.
TEST_F(MapDiff, IdenticalGridsWithOtherOffsetsDiffer) {
  write_grid(dir_.file("here.map"), base_grid(), GlobalOffset{0, 0, 0});
  write_grid(dir_.file("there.map"), base_grid(), GlobalOffset{1.9e8, 0, 0});
  const ToolRun r = mapdiff({dir_.file("here.map"), dir_.file("there.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "verdict: different: identical GRIDMAPs at other places")) << r.output;
  EXPECT_EQ(mapdiff({"--tolerance", "0.5", dir_.file("here.map"), dir_.file("there.map")}).status, 1);
  const ToolRun ignored = mapdiff({"--no-offset", dir_.file("here.map"), dir_.file("there.map")});
  EXPECT_EQ(ignored.status, 0) << ignored.output;
  EXPECT_TRUE(contains(ignored.output, "verdict: identical\n")) << ignored.output;
}

// --png must name a new or regular file that is neither input: an empty
// name, an input spelled another way, a FIFO and a link to a device are
// refused before anything is written, and left as they were.
TEST_F(MapDiff, PngTargetsThatMustNotBeReplacedAreRefused) {
  const std::string a_bytes = maptest::read_bytes(a_);
  ASSERT_EQ(::mkfifo(dir_.file("pipe.png").c_str(), 0600), 0);
  ASSERT_EQ(::symlink("/dev/null", dir_.file("null.png").c_str()), 0);
  const std::vector<std::string> before = dir_.entries();
  const ToolRun empty = mapdiff({"--png", "", a_, a_});
  EXPECT_EQ(empty.status, 2);
  EXPECT_TRUE(contains(empty.output, "--png needs a file name")) << empty.output;
  const ToolRun input = mapdiff({"--png", dir_.path() + "/./a.map", a_, a_});
  EXPECT_EQ(input.status, 2);
  EXPECT_TRUE(contains(input.output, "is the input")) << input.output;
  const ToolRun fifo = mapdiff({"--png", dir_.file("pipe.png"), a_, a_});
  EXPECT_EQ(fifo.status, 2);
  EXPECT_TRUE(contains(fifo.output, "is a FIFO")) << fifo.output;
  const ToolRun dev = mapdiff({"--png", dir_.file("null.png"), a_, a_});
  EXPECT_EQ(dev.status, 2);
  EXPECT_TRUE(contains(dev.output, "is a character device")) << dev.output;
  EXPECT_EQ(maptest::read_bytes(a_), a_bytes);
  EXPECT_EQ(dir_.entries(), before);
  struct stat st;
  ASSERT_EQ(::lstat(dir_.file("null.png").c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode));
}

TEST_F(MapDiff, OneCellChanged) {
  const std::string b = write_b([](GridMap &g) { g.at(3, 2) = 0.375f; });
  const ToolRun r = mapdiff({a_, b});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "identical: no")) << r.output;
  EXPECT_TRUE(contains(r.output, "(3, 2)  A 0.125  B 0.375  dp +0.25\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "max |dp| (known in both) 0.25")) << r.output;
  EXPECT_TRUE(contains(r.output, "verdict: different: 1 cell differs (max |dp| 0.25,")) << r.output;
  const ToolRun quiet = mapdiff({"-q", a_, b});
  EXPECT_EQ(quiet.status, 1);
  EXPECT_EQ(quiet.output.find('\n'), quiet.output.size() - 1) << quiet.output;  // one line
}

TEST_F(MapDiff, ToleranceOptions) {
  const std::string b = write_b([](GridMap &g) { g.at(3, 2) = 0.375f; });
  const ToolRun within = mapdiff({"--tolerance", "0.25", a_, b});
  EXPECT_EQ(within.status, 0) << within.output;
  EXPECT_TRUE(contains(within.output, "verdict: within tolerance: 1 cell differs")) << within.output;
  const ToolRun outside = mapdiff({"--tolerance", "0.2", a_, b});
  EXPECT_EQ(outside.status, 1) << outside.output;
  EXPECT_TRUE(contains(outside.output, "outside tolerance: max |dp| 0.25 > 0.2")) << outside.output;
  // A class flip (free 0.125 -> occupied 0.625): 23 of 24 cells agree.
  const std::string flip = write_b([](GridMap &g) { g.at(3, 2) = 0.625f; }, "flip.map");
  // Unless asked for, the class agreement is not checked: the flip is within --tolerance.
  EXPECT_EQ(mapdiff({"--tolerance", "0.5", a_, flip}).status, 0);
  EXPECT_EQ(mapdiff({"--tolerance", "0.4", a_, flip}).status, 1);
  EXPECT_EQ(mapdiff({"--tolerance", "0.5", "--min-class-agreement", "0.95", a_, flip}).status, 0);
  EXPECT_EQ(mapdiff({"--tolerance", "0.5", "--min-class-agreement", "0.96", a_, flip}).status, 1);
}

TEST_F(MapDiff, StatusChangeIsCounted) {
  const std::string b = write_b([](GridMap &g) {
    g.at(1, 1) = carmen::kUnknownCell;  // known -> unknown
    g.at(0, 0) = 0.5f;                  // unknown -> known
  });
  const ToolRun r = mapdiff({a_, b});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "known/unknown differs 2 ")) << r.output;
  EXPECT_TRUE(contains(r.output, "(0, 0)  A -1  B 0.5\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "(1, 1)  A 0.125  B -1\n")) << r.output;
  EXPECT_EQ(mapdiff({"--max-status-differs", "2", a_, b}).status, 0);
  EXPECT_EQ(mapdiff({"--max-status-differs", "1", a_, b}).status, 1);
  const ToolRun classes = mapdiff({"--max-status-differs", "2", "--min-class-agreement", "1", a_, b});
  EXPECT_EQ(classes.status, 1);
  EXPECT_TRUE(contains(classes.output, "outside tolerance: class agreement 0.916667 < 1")) << classes.output;
}

TEST_F(MapDiff, TopListsLargestFirst) {
  const std::string b = write_b([](GridMap &g) {
    g.at(1, 0) = 0.25f;  // +0.125
    g.at(4, 2) = 1.0f;   // +0.875
    g.at(2, 1) = 0.25f;  // -0.5
  });
  const ToolRun r = mapdiff({"--top", "2", a_, b});
  EXPECT_EQ(r.status, 1);
  const size_t first = r.output.find("(4, 2)  A 0.125  B 1"), second = r.output.find("(2, 1)  A 0.75  B 0.25");
  EXPECT_NE(first, std::string::npos) << r.output;
  EXPECT_NE(second, std::string::npos) << r.output;
  EXPECT_LT(first, second) << r.output;
  EXPECT_FALSE(contains(r.output, "(1, 0)")) << r.output;
  EXPECT_TRUE(contains(r.output, "2 of 3 cells that differ")) << r.output;
  EXPECT_FALSE(contains(mapdiff({"--top", "0", a_, b}).output, "(4, 2)"));
}

TEST_F(MapDiff, DifferentSizesCompareTheOverlap) {
  write_grid(dir_.file("small.map"), crop(base_grid(), 0, 0, 4, 3));
  const ToolRun r = mapdiff({a_, dir_.file("small.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "size 4 x 3 cells")) << r.output;
  EXPECT_TRUE(contains(r.output, "alignment: at cell (0, 0) (no OFFSET chunk in either)")) << r.output;
  EXPECT_TRUE(contains(r.output, "compared: 4 x 3 cells, A's x 0..3, y 0..2; "
                                 "outside the overlap 12 cells (12 known)")) << r.output;
  EXPECT_TRUE(contains(r.output, "bit-identical 100.0000%")) << r.output;
  EXPECT_TRUE(contains(r.output, "verdict: different: 12 cells differ")) << r.output;
  // Outside cells share the known/unknown budget.
  EXPECT_EQ(mapdiff({"--max-status-differs", "12", a_, dir_.file("small.map")}).status, 0);
  EXPECT_EQ(mapdiff({"--max-status-differs", "11", a_, dir_.file("small.map")}).status, 1);
}

// Two windows of one 10 x 8 map (0.5 m cells, cell (0, 0) at (-2, 3)):
// A = x 1..7, y 2..6; B = x 3..9, y 0..5. They overlap in x 3..7, y 2..5,
// which is A's x 2..6, y 0..3; B's cell (0, 0) is A's cell (2, -2).
class MapDiffOffsets : public MapDiff {
 protected:
  void SetUp() override {
    MapDiff::SetUp();
    world_ = GridMap::filled(10, 8, 0.5, 0.25f);
    for (int x = 0; x < 10; ++x) world_.at(x, (x * 3) % 8) = 0.875f;
    world_.at(4, 3) = carmen::kUnknownCell;
    a_ = dir_.file("wa.map");
    write_grid(a_, crop(world_, 1, 2, 7, 5), GlobalOffset{-2 + 0.5, 3 + 1.0, 0});
  }
  std::string write_window_b(const GridMap &world, double dx = 0) {
    write_grid(dir_.file("wb.map"), crop(world, 3, 0, 7, 6), GlobalOffset{-2 + 1.5 + dx, 3, 0});
    return dir_.file("wb.map");
  }
  GridMap world_;
};

TEST_F(MapDiffOffsets, AlignByOffset) {
  const std::string b = write_window_b(world_);
  const ToolRun r = mapdiff({a_, b});
  EXPECT_EQ(r.status, 1) << r.output;  // the sizes differ
  EXPECT_TRUE(contains(r.output, "alignment: by OFFSET: B's cell (0, 0) is A's cell (2, -2)")) << r.output;
  EXPECT_TRUE(contains(r.output, "compared: 5 x 4 cells, A's x 2..6, y 0..3; outside the overlap 37 cells"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "bit-identical 100.0000%")) << r.output;
  EXPECT_EQ(mapdiff({"--max-status-differs", "37", a_, b}).status, 0);
  // Without the offsets the windows do not match.
  const ToolRun plain = mapdiff({"--no-offset", a_, b});
  EXPECT_TRUE(contains(plain.output, "alignment: at cell (0, 0) (--no-offset)")) << plain.output;
  EXPECT_FALSE(contains(plain.output, "bit-identical 100.0000%")) << plain.output;
}

TEST_F(MapDiffOffsets, ChangedCellInAsCoordinates) {
  GridMap world = world_;
  world.at(5, 4) = 0.5f;  // A's (4, 2), B's (2, 4)
  const ToolRun r = mapdiff({a_, write_window_b(world)});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "(4, 2)  A 0.25  B 0.5  dp +0.25  [B's cell (2, 4)]")) << r.output;
}

TEST_F(MapDiffOffsets, FractionalOffsetAlignsAtOrigin) {
  const ToolRun r = mapdiff({a_, write_window_b(world_, 0.2)});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "at cell (0, 0), not by OFFSET: "
                                 "the offsets are not a whole number of cells apart")) << r.output;
}

TEST_F(MapDiff, DifferentResolution) {
  GridMap g = base_grid();
  g.resolution = 0.05;
  write_grid(dir_.file("fine.map"), g);
  const ToolRun r = mapdiff({"--png", dir_.file("d.png"), a_, dir_.file("fine.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "resolution 0.0500000007 m")) << r.output;
  EXPECT_TRUE(contains(r.output, "verdict: different: resolution 0.100000001 m vs 0.0500000007 m")) << r.output;
  EXPECT_FALSE(maptest::file_exists(dir_.file("d.png")));
}

TEST_F(MapDiff, UnreadableFilesExitTwoNamingThem) {
  const std::string missing = dir_.file("nope.map");
  ToolRun r = mapdiff({a_, missing});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "mapdiff: " + missing + ": ")) << r.output;
  r = mapdiff({missing, a_});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, missing)) << r.output;

  const std::string garbage = dir_.file("garbage.map");
  maptest::write_bytes(garbage, std::string("\x01\x02not a map at all\xff\xfe", 20));
  r = mapdiff({a_, garbage});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "mapdiff: " + garbage + ": ")) << r.output;
  maptest::write_bytes(dir_.file("garbage.map.gz"), "not gzip either");
  r = mapdiff({dir_.file("garbage.map.gz"), a_});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, dir_.file("garbage.map.gz"))) << r.output;

  carmen::write_map_file(dir_.file("nogrid.map"), carmen::MapFile{});
  r = mapdiff({a_, dir_.file("nogrid.map")});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, dir_.file("nogrid.map") + ": has no GRIDMAP chunk")) << r.output;
}

TEST_F(MapDiff, FailedRunLeavesNoPicture) {
  const std::vector<std::string> before = dir_.entries();
  const ToolRun r = mapdiff({"--png", dir_.file("d.png"), a_, dir_.file("nope.map")});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(dir_.entries(), before);  // no picture, no temporary
  const ToolRun unwritable = mapdiff({"--png", dir_.file("no/dir/d.png"), a_, a_});
  EXPECT_EQ(unwritable.status, 2);
  EXPECT_TRUE(contains(unwritable.output, dir_.file("no/dir/d.png"))) << unwritable.output;
  EXPECT_EQ(dir_.entries(), before);
}

TEST_F(MapDiffOffsets, PngShowsTheOverlap) {
  GridMap world = world_;
  world.at(5, 4) = 0.5f;                   // B higher: A's (4, 2)
  world.at(3, 3) = 0.125f;                 // B lower: A's (2, 1)
  world.at(6, 5) = carmen::kUnknownCell;  // known in A only: A's (5, 3)
  const std::string png = dir_.file("d.png");
  const ToolRun r = mapdiff({"--png", png, a_, write_window_b(world)});
  EXPECT_EQ(r.status, 1) << r.output;
  RgbImage img;
  ASSERT_TRUE(read_png_rgb(png, &img)) << r.output;
  ASSERT_GE(img.width, 5);  // the overlap, A's x 2..6, y 0..3, at the top left; the legend below
  ASSERT_GT(img.height, 4);
  // Column = x - 2, row = 3 - y (row 0 is the highest y).
  const uint8_t *higher = img.pixel(4 - 2, 3 - 2), *lower = img.pixel(2 - 2, 3 - 1);
  const uint8_t *status = img.pixel(5 - 2, 3 - 3), *same = img.pixel(3 - 2, 3 - 0);
  EXPECT_EQ(higher[0], 255);
  EXPECT_LT(higher[1], 128);
  EXPECT_EQ(higher[1], higher[2]);
  EXPECT_EQ(lower[2], 255);
  EXPECT_LT(lower[0], 128);
  EXPECT_EQ(lower[0], lower[1]);
  EXPECT_EQ(status[0], 255);
  EXPECT_EQ(status[1], 0);
  EXPECT_EQ(status[2], 255);
  // An unchanged free cell (p = 0.25) is A's grey, round(255 * 0.75).
  EXPECT_EQ(same[0], 191);
  EXPECT_EQ(same[1], 191);
  EXPECT_EQ(same[2], 191);
  for (const std::string &name : dir_.entries()) EXPECT_EQ(name.find(".tmp."), std::string::npos) << name;
}

TEST_F(MapDiff, Json) {
  const std::string b = write_b([](GridMap &g) { g.at(3, 2) = 0.375f; });
  const ToolRun r = mapdiff({"--json", a_, b});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.output.substr(0, 6), "{\"a\":{") << r.output;
  EXPECT_TRUE(contains(r.output, "\"max_abs_dp\":0.25,")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"largest\":[{\"x\":3,\"y\":2,\"a\":0.125,\"b\":0.375}]")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"identical\":false,\"offsets_equal\":true,")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"exit\":1}\n")) << r.output;
}

// Pixels of exactly this colour in rows from `first_row` down.
size_t count_colour(const RgbImage &img, int first_row, uint8_t r, uint8_t g, uint8_t b) {
  size_t n = 0;
  for (int row = first_row; row < img.height; ++row)
    for (int col = 0; col < img.width; ++col) {
      const uint8_t *p = img.pixel(col, row);
      n += p[0] == r && p[1] == g && p[2] == b;
    }
  return n;
}

// The legend below the picture: a swatch of every difference colour, the
// |dp| ramp, A's grey ramp, the unknown colour and black text.
TEST_F(MapDiff, PngHasALegend) {
  GridMap a = base_grid();
  a.at(0, 0) = carmen::kUnknownCell;  // unknown in both: the unknown colour in the picture
  write_grid(a_, a);
  const std::string b = write_b([](GridMap &g) {
    g.at(0, 0) = carmen::kUnknownCell;
    g.at(1, 1) = 0.9f;
  });
  const std::string png = dir_.file("d.png");
  const ToolRun r = mapdiff({"--png", png, a_, b});
  EXPECT_EQ(r.status, 1) << r.output;
  RgbImage img;
  ASSERT_TRUE(read_png_rgb(png, &img)) << r.output;
  const int grid_h = base_grid().size_y;
  ASSERT_GT(img.height, grid_h + 40);  // the legend's lines
  ASSERT_GE(img.width, base_grid().size_x);
  EXPECT_TRUE(contains(r.output, "picture: " + png + " (" + std::to_string(img.width) + " x " +
                                     std::to_string(img.height)))
      << r.output;
  const int legend = grid_h + 1;
  EXPECT_GT(count_colour(img, legend, 255, 0, 0), 10u);      // red, B higher (full |dp|)
  EXPECT_GT(count_colour(img, legend, 0, 0, 255), 10u);      // blue, B lower
  EXPECT_GT(count_colour(img, legend, 255, 0, 255), 10u);    // magenta, known in A only
  EXPECT_GT(count_colour(img, legend, 0, 200, 0), 10u);      // green, known in B only
  EXPECT_GT(count_colour(img, legend, 255, 170, 170), 0u);   // the ramp's pale end, |dp| 1e-6
  size_t mid_greys = 0;  // A's grey ramp: the greys between white and black
  for (int v = 16; v < 240; ++v) mid_greys += count_colour(img, legend, uint8_t(v), uint8_t(v), uint8_t(v));
  EXPECT_GT(mid_greys, 40u);
  EXPECT_GT(count_colour(img, legend, 0x70, 0x89, 0x86), 10u);  // unknown
  EXPECT_GT(count_colour(img, legend, 0, 0, 0), 200u);       // text
  // In the picture: the cell unknown in both has the unknown colour.
  const uint8_t *u = img.pixel(0, grid_h - 1);
  EXPECT_EQ(u[0], 0x70);
  EXPECT_EQ(u[1], 0x89);
  EXPECT_EQ(u[2], 0x86);
}

// Nothing differs: the legend says IDENTICAL (no difference swatches).
TEST_F(MapDiff, PngOfIdenticalMapsSaysSo) {
  const std::string png = dir_.file("same.png");
  const ToolRun r = mapdiff({"--png", png, a_, a_});
  EXPECT_EQ(r.status, 0) << r.output;
  RgbImage img;
  ASSERT_TRUE(read_png_rgb(png, &img)) << r.output;
  const int grid_h = base_grid().size_y;
  ASSERT_GT(img.height, grid_h + 20);
  EXPECT_EQ(count_colour(img, grid_h + 1, 255, 0, 255), 0u);
  EXPECT_EQ(count_colour(img, grid_h + 1, 0, 200, 0), 0u);
  EXPECT_GT(count_colour(img, grid_h + 1, 0, 0, 0), 100u);
  const ToolRun diff = mapdiff({"--png", dir_.file("d.png"), a_, write_b([](GridMap &g) { g.at(1, 1) = 0.9f; })});
  RgbImage other;
  ASSERT_TRUE(read_png_rgb(dir_.file("d.png"), &other)) << diff.output;
  EXPECT_GT(other.height, img.height);  // the difference lines are left out when identical
}

// ---- The library ----------------------------------------------------------

TEST(CompareGrids, AgreesWithCompareMapsAtNoShift) {
  GridMap a = base_grid(), b = base_grid();
  b.at(3, 2) = 0.625f;
  b.at(1, 1) = carmen::kUnknownCell;
  const carmen::Agreement m = carmen::compare_maps(a.cells, b.cells);
  const carmen::GridComparison g = carmen::compare_grids(a, b, 0, 0, 10);
  EXPECT_EQ(g.agreement.cells, m.cells);
  EXPECT_EQ(g.agreement.identical, m.identical);
  EXPECT_EQ(g.agreement.status_differs, m.status_differs);
  EXPECT_EQ(g.agreement.class_agree, m.class_agree);
  EXPECT_EQ(g.agreement.max_abs_diff, m.max_abs_diff);
  EXPECT_EQ(g.agreement.table("t"), m.table("t"));
  EXPECT_EQ(g.outside, 0u);
  EXPECT_EQ(g.differing_cells(), 2u);
  ASSERT_EQ(g.largest.size(), 1u);
  EXPECT_EQ(g.largest[0].x, 3);
  ASSERT_EQ(g.status_changes.size(), 1u);
  EXPECT_EQ(g.status_changes[0].y, 1);
}

TEST(CompareGrids, NoOverlap) {
  const GridMap a = base_grid();
  const carmen::GridComparison g = carmen::compare_grids(a, a, 6, 0, 10);
  EXPECT_EQ(g.width, 0);
  EXPECT_EQ(g.height, 0);
  EXPECT_EQ(g.outside, 48u);
  EXPECT_EQ(g.outside_known, 46u);
  EXPECT_FALSE(g.same_cells());
}

TEST(CompareGrids, OffsetShift) {
  int64_t sx = 0, sy = 0;
  std::string why;
  EXPECT_TRUE(carmen::offset_shift({1.0, 2.0, 0}, {1.5, 1.0, 0}, 0.25, &sx, &sy, &why));
  EXPECT_EQ(sx, 2);
  EXPECT_EQ(sy, -4);
  EXPECT_FALSE(carmen::offset_shift({0, 0, 0}, {0.1, 0, 0}, 0.25, &sx, &sy, &why));
  EXPECT_TRUE(contains(why, "whole number")) << why;
  EXPECT_FALSE(carmen::offset_shift({0, 0, 0.5}, {0, 0, 0.5}, 0.25, &sx, &sy, &why));
  EXPECT_TRUE(contains(why, "theta")) << why;
}

// ---------------------------------------------------------------------------
// Every format of the map table (carmen_compat/map_format.h)
// ---------------------------------------------------------------------------

// Writes `g` at `path` in the format of its name, through the format table.
std::string write_any(const std::string &path, const GridMap &g, std::optional<GlobalOffset> origin = std::nullopt) {
  carmen::MapToWrite m;
  m.grid = g;
  m.origin = origin;
  carmen::write_map(path, m);
  return path;
}

const GlobalOffset kOrigin{1.5, -2.25, 0};

TEST_F(MapDiff, TwoPgmMaps) {
  const std::string a = write_any(dir_.file("a.pgm"), base_grid(), kOrigin);
  const std::string b = write_any(dir_.file("b.pgm"), base_grid(), kOrigin);
  ToolRun r = mapdiff({a, b});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "A: " + a + " (ROS map_server / nav2 PGM image with a .yaml beside it; "
                                          "its origin is the offset)\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "offset x 1.5 y -2.25 theta 0\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "verdict: identical\n")) << r.output;

  // A free cell made occupied: one cell differs, in A's coordinates.
  GridMap g = base_grid();
  g.at(4, 1) = 1.0f;
  write_any(b, g, kOrigin);
  r = mapdiff({a, b});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "alignment: by OFFSET: B's cell (0, 0) is A's cell (0, 0)")) << r.output;
  EXPECT_TRUE(contains(r.output, "verdict: different: 1 cell differs")) << r.output;
  EXPECT_TRUE(contains(r.output, "  (4, 1)  A ")) << r.output;

  // Moved by two cells: aligned by the origins.
  write_any(b, crop(base_grid(), 2, 0, 4, 4), GlobalOffset{kOrigin.x + 0.2, kOrigin.y, 0});
  r = mapdiff({"--max-status-differs", "8", a, b});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "alignment: by OFFSET: B's cell (0, 0) is A's cell (2, 0)")) << r.output;
}

TEST_F(MapDiff, PngYamlPairReadsAsItsPgm) {
  const std::string a = write_any(dir_.file("a.pgm"), base_grid(), kOrigin);
  const std::string b = write_any(dir_.file("b.png+yaml"), base_grid(), kOrigin);
  EXPECT_TRUE(maptest::file_exists(dir_.file("b.png")) && maptest::file_exists(dir_.file("b.yaml")));
  const ToolRun r = mapdiff({a, b});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "B: " + b + " (ROS map_server / nav2 pair NAME.png + NAME.yaml; ")) << r.output;
  EXPECT_TRUE(contains(r.output, "verdict: identical\n")) << r.output;
  // The map_server YAML names the same map.
  EXPECT_EQ(mapdiff({"-q", dir_.file("b.yaml"), a}).output, "identical\n");
  const ToolRun j = mapdiff({"--json", a, b});
  EXPECT_TRUE(contains(j.output, "\"format\":\".pgm\"}")) << j.output;
  EXPECT_TRUE(contains(j.output, "\"format\":\".png+yaml\"}")) << j.output;
}

// A CARMEN map and its map_server conversion: the same resolution (a YAML's
// 0.1 is the GRIDMAP's float32 0.1), the same place, the same classes; the
// trinary image keeps the classes, not the values.
TEST_F(MapDiff, CarmenMapAgainstItsPgmConversion) {
  write_grid(a_, base_grid(), kOrigin);
  const std::string b = write_any(dir_.file("conv.pgm"), base_grid(), kOrigin);
  ToolRun r = mapdiff({a_, b});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "A: " + a_ + "\n")) << r.output;  // a CARMEN map, named as before
  EXPECT_TRUE(contains(r.output, "size 6 x 4 cells, resolution 0.100000001 m, offset x 1.5 y -2.25 theta 0\n"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "alignment: by OFFSET: B's cell (0, 0) is A's cell (0, 0)")) << r.output;
  EXPECT_TRUE(contains(r.output, "class agreement 1.000000)")) << r.output;
  r = mapdiff({"-q", "--tolerance", "1", "--min-class-agreement", "1", a_, b});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.substr(0, 17), "within tolerance:") << r.output;
  // The other way round, and from standard input (a CARMEN map).
  const std::string out = dir_.file("out.txt");
  EXPECT_EQ(tooltest::run_tool_piped(a_, "mapdiff",
                                     {"-q", "--tolerance", "1", "--min-class-agreement", "1", b, "-"}, out), 0);
}

// A picture has no resolution and no origin: it takes the other map's
// resolution and lies at cell (0, 0); its greys give p back to 1/510.
TEST_F(MapDiff, PictureTakesTheOtherMapsResolution) {
  write_grid(a_, base_grid(), kOrigin);
  const std::string b = write_any(dir_.file("pic.png"), base_grid());
  ToolRun r = mapdiff({a_, b});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "B: " + b + " (picture for people (RGB); no resolution of its own: the other map's)"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "resolution 0.100000001 m, offset none")) << r.output;
  EXPECT_TRUE(contains(r.output, "alignment: at cell (0, 0) (B is a picture: a .png has no origin)")) << r.output;
  EXPECT_TRUE(contains(r.output, "known/unknown differs 0")) << r.output;
  EXPECT_EQ(mapdiff({"-q", "--tolerance", "0.002", b, a_}).status, 0);
  // Two pictures: both without a resolution, compared cell for cell.
  EXPECT_EQ(mapdiff({"-q", b, write_any(dir_.file("pic2.png"), base_grid())}).output, "identical\n");
}

TEST_F(MapDiff, MapServerFilesThatCannotBeReadExitTwoNamingThem) {
  const std::string a = write_any(dir_.file("a.pgm"), base_grid(), kOrigin);
  ASSERT_EQ(std::remove(dir_.file("a.yaml").c_str()), 0);
  ToolRun r = mapdiff({a_, a});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "mapdiff: ")) << r.output;
  EXPECT_TRUE(contains(r.output, dir_.file("a.yaml"))) << r.output;
  maptest::write_bytes(dir_.file("bad.yaml"), "image: nowhere.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n");
  r = mapdiff({dir_.file("bad.yaml"), a_});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "nowhere.pgm")) << r.output;
  // --png must not replace a pair's YAML.
  const std::string p = write_any(dir_.file("p.pgm"), base_grid(), kOrigin);
  r = mapdiff({"--png", dir_.file("p.yaml"), a_, p});
  EXPECT_EQ(r.status, 2) << r.output;
}

}  // namespace
