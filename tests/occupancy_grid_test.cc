// carmen_compat/occupancy_grid.h: a map as nav_msgs/OccupancyGrid data.
#include "carmen_compat/occupancy_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "carmen_compat/image_io.h"

namespace {

using carmen::GridMap;
using carmen::MapServerOptions;
using carmen::PgmMode;

// 3 wide, 2 high, x-major; values exact in float32.
GridMap small_map() {
  GridMap m = GridMap::filled(3, 2, 0.05);
  m.cells = {-1.0f, 0.125f,  // x 0: y 0, y 1
             0.5f, 0.6875f,  // x 1
             0.1875f, 2.0f}; // x 2 (y 1 off-limits)
  return m;
}

MapServerOptions mode(PgmMode m, double free_thresh = 0.196, double occupied_thresh = 0.65) {
  MapServerOptions o;
  o.mode = m;
  o.free_thresh = free_thresh;
  o.occupied_thresh = occupied_thresh;
  return o;
}

TEST(OccupancyGridData, RowsFromTheBottomByHand) {
  const GridMap m = small_map();
  // rows from y 0: (x0, x1, x2) = (-1, 0.5, 0.1875), then (0.125, 0.6875, off-limits)
  EXPECT_EQ(carmen::occupancy_grid_data(m, mode(PgmMode::Raw)), (std::vector<int8_t>{-1, 50, 19, 13, 69, 100}));
  EXPECT_EQ(carmen::occupancy_grid_data(m, mode(PgmMode::Trinary)), (std::vector<int8_t>{-1, -1, 0, 0, 100, 100}));
  EXPECT_EQ(carmen::occupancy_grid_data(m, mode(PgmMode::Trinary, 0.1, 0.7)),
            (std::vector<int8_t>{-1, -1, -1, -1, -1, 100}));
}

// What map_server publishes for the picture our writer makes (image_io.h's
// pixels, row 0 at the top, read back by map_server's rules) is what the
// data says, cell for cell, on a map larger than a tile with every kind of
// value.
TEST(OccupancyGridData, EqualsMapServersReadingOfOurPicture) {
  GridMap m = GridMap::filled(131, 97, 0.05);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> p(0.0f, 1.0f);
  for (size_t i = 0; i < m.cells.size(); ++i) m.cells[i] = i % 11 == 0 ? -1.0f : i % 37 == 0 ? 2.0f : p(rng);
  const size_t w = 131, h = 97;
  for (const PgmMode pm : {PgmMode::Trinary, PgmMode::Raw}) {
    const MapServerOptions o = mode(pm);
    const std::vector<uint8_t> pixels = carmen::map_to_pgm_pixels(m, o);
    const std::vector<int8_t> data = carmen::occupancy_grid_data(m, o);
    ASSERT_EQ(data.size(), w * h);
    for (size_t y = 0; y < h; ++y) {
      for (size_t x = 0; x < w; ++x) {
        const uint8_t level = pixels[(h - 1 - y) * w + x];
        int8_t want;
        if (pm == PgmMode::Raw) {
          want = static_cast<int8_t>(level);  // 255 (unknown) is -1
        } else {
          const double occ = (255 - level) / 255.0;  // map_server's trinary reading, negate 0
          want = occ > o.occupied_thresh ? 100 : occ < o.free_thresh ? 0 : -1;
        }
        ASSERT_EQ(data[y * w + x], want) << "cell " << x << ", " << y << " value " << m.cells[x * h + y];
      }
    }
  }
}

// map_server compares doubles: the float nearest a threshold falls on the side its double
// value does. float(0.65) is 0.64999997615814 (below: not occupied), the next float
// 0.65000003576279 (above); float(0.196) is 0.19599999487400 (below: free), the next float
// 0.19600000977516 (not free).
TEST(OccupancyGridData, ThresholdsCompareAsDoubles) {
  GridMap m = GridMap::filled(4, 1, 0.05);
  const float occ = 0.65f, free = 0.196f;
  ASSERT_LT(double(occ), 0.65);
  ASSERT_LT(double(free), 0.196);
  m.cells = {occ, std::nextafter(occ, 1.0f), free, std::nextafter(free, 1.0f)};
  EXPECT_EQ(carmen::occupancy_grid_data(m, mode(PgmMode::Trinary)), (std::vector<int8_t>{-1, 100, 0, -1}));
  // a threshold that is a float: equal is neither above nor below
  m.cells = {0.5f, std::nextafter(0.5f, 1.0f), 0.25f, std::nextafter(0.25f, 0.0f)};
  EXPECT_EQ(carmen::occupancy_grid_data(m, mode(PgmMode::Trinary, 0.25, 0.5)), (std::vector<int8_t>{-1, 100, -1, 0}));
}

TEST(OccupancyGridData, RefusesWhatHasNoMeaning) {
  const GridMap m = small_map();
  EXPECT_THROW(carmen::occupancy_grid_data(m, mode(PgmMode::Scale)), std::invalid_argument);
  MapServerOptions negated = mode(PgmMode::Trinary);
  negated.negate = true;
  EXPECT_THROW(carmen::occupancy_grid_data(m, negated), std::invalid_argument);
  GridMap wrong = m;
  wrong.cells.pop_back();
  EXPECT_THROW(carmen::occupancy_grid_data(wrong, mode(PgmMode::Raw)), std::invalid_argument);
}

}  // namespace
