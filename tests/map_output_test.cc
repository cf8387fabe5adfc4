// vasco_gpu/map_output.h: a finished map's world origin, worked out by hand.
#include "vasco_gpu/map_output.h"

#include <gtest/gtest.h>

namespace {

// A 400 x 200 grid of 0.05 m cells centred on the laser at (10, -4): fine
// cell (gx, gy)'s corner is at ((gx - 200) * 0.05 + 10, (gy - 100) * 0.05 - 4).
// Finish with downsample 4 cropped at (min_x, min_y) = (3, 5) starts at fine
// cell (12, 20): (-188 * 0.05 + 10, -80 * 0.05 - 4) = (0.6, -8).
TEST(MapOutput, OriginIsTheCropCornerInTheWorld) {
  vasco::GridGeometry geo;
  geo.size_x = 400;
  geo.size_y = 200;
  geo.resolution = 0.05;
  geo.x0 = 10;
  geo.y0 = -4;
  vasco::FinishedMap f;
  f.size_x = 2;
  f.size_y = 3;
  f.resolution = 0.2;
  f.min_x = 3;
  f.min_y = 5;
  f.downsample = 4;
  f.cells = {0.f, 1.f, -1.f, 0.5f, 0.25f, 0.75f};
  const carmen::GlobalOffset o = vasco::world_origin(f, geo);
  EXPECT_NEAR(o.x, 0.6, 1e-12);
  EXPECT_NEAR(o.y, -8.0, 1e-12);
  EXPECT_EQ(o.theta, 0.0);
  const carmen::MapToWrite m = vasco::map_to_write(f, geo);
  ASSERT_TRUE(m.origin);
  EXPECT_EQ(m.origin->x, o.x);
  EXPECT_EQ(m.grid.size_x, 2);
  EXPECT_EQ(m.grid.size_y, 3);
  EXPECT_EQ(m.grid.resolution, 0.2);
  EXPECT_EQ(m.grid.cells, f.cells);
}

}  // namespace
