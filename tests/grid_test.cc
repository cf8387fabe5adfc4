// Grid sizing (DESIGN §3) and finish (DESIGN §2 step 7) on cases worked out by hand.
#include "vasco_gpu/grid.h"

#include <gtest/gtest.h>

#include <climits>
#include <cmath>

#include "vasco_gpu/error.h"
#include "vasco_gpu/internal/oracle.h"

#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {
namespace {

std::vector<float> unknown(int sx, int sy) { return std::vector<float>(size_t(sx) * sy, -1.0f); }

TEST(FinishGrid, BlockMeansCropAndTheMissingPlusOne) {
  // 8 x 6 cells, three known.
  auto c = unknown(8, 6);
  c[2 * 6 + 3] = 0.2f;
  c[3 * 6 + 3] = 0.4f;
  c[5 * 6 + 1] = 0.9f;
  // ds 2 -> 4 x 3 blocks; known blocks (1,1) = mean(0.2, 0.4), (2,0) = 0.9.
  const float mean = (float)(((double)0.2f + (double)0.4f) / 2.0);

  // border 0: x bounds 1..2, y bounds 0..1 -> size (2-1) x (1-0) = 1 x 1,
  // cell (0,0) = block (1,0): unknown.
  FinishedMap m0 = finish_grid(c.data(), 8, 6, 0.05, 2, 0);
  EXPECT_EQ(m0.size_x, 1);
  EXPECT_EQ(m0.size_y, 1);
  EXPECT_EQ(m0.min_x, 1);
  EXPECT_EQ(m0.min_y, 0);
  EXPECT_DOUBLE_EQ(m0.resolution, 0.1);
  EXPECT_EQ(m0.cells[0], -1.0f);

  // border 1: bounds start at min 4-1-1 = 2, max 1 (x) and min 1, max 1 (y);
  // widened to x 1..2, y 0..1; then -1/+1 and clamped: x 0..3, y 0..2.
  FinishedMap m1 = finish_grid(c.data(), 8, 6, 0.05, 2, 1);
  EXPECT_EQ(m1.size_x, 3);
  EXPECT_EQ(m1.size_y, 2);
  EXPECT_EQ(m1.min_x, 0);
  EXPECT_EQ(m1.min_y, 0);
  EXPECT_EQ(m1.cells[1 * 2 + 1], mean);
  EXPECT_EQ(m1.cells[2 * 2 + 0], 0.9f);
  EXPECT_EQ(m1.cells[0], -1.0f);
}

TEST(FinishGrid, DownsampleOneKeepsValues) {
  auto c = unknown(4, 4);
  c[1 * 4 + 2] = 0.25f;
  FinishedMap m = finish_grid(c.data(), 4, 4, 0.1, 1, 5);
  // bounds: min 4-5-1 = -2 -> widened? no (1 > -2); max 5 -> stays. Then
  // min -5 -> 0, max 10 -> 3: size 3 x 3.
  EXPECT_EQ(m.size_x, 3);
  EXPECT_EQ(m.size_y, 3);
  EXPECT_EQ(m.cells[1 * 3 + 2], 0.25f);
}

TEST(FinishGrid, RejectsBadArguments) {
  auto c = unknown(4, 4);
  EXPECT_THROW(finish_grid(c.data(), 4, 4, 0.1, 0, 1), Error);
  EXPECT_THROW(finish_grid(c.data(), 4, 4, 0.1, 2, -1), Error);
}

TEST(FinishGrid, HugeBordersCropToTheGridWithoutOverflow) {
  // 10 x 6 cells, ds 2 -> 5 x 3 blocks, one known cell. Any border at least
  // the grid's clamps every bound: blocks 0 .. n - 1, size n - 1 (the
  // missing +1), whatever CARMEN's int arithmetic would have wrapped to.
  auto c = unknown(10, 6);
  c[4 * 6 + 2] = 0.7f;
  for (int border : {5, 1000, INT_MAX / 2, INT_MAX - 1, INT_MAX}) {
    const FinishedMap m = finish_grid(c.data(), 10, 6, 0.1, 2, border);
    EXPECT_EQ(m.min_x, 0) << border;
    EXPECT_EQ(m.min_y, 0) << border;
    EXPECT_EQ(m.size_x, 4) << border;
    EXPECT_EQ(m.size_y, 2) << border;
    EXPECT_EQ(m.cells[2 * 2 + 1], 0.7f) << border;
  }
  // Nothing known and a huge border: the same whole-grid crop, all unknown.
  const FinishedMap none = finish_grid(unknown(10, 6).data(), 10, 6, 0.1, 2, INT_MAX);
  EXPECT_EQ(none.size_x, 4);
  EXPECT_EQ(none.size_y, 2);
}

TEST(SizeGrid, TwiceTheExtentPlusReachPlusTwo) {
  ScanBatch b;
  float r = 1.0f;
  b.add_scan(1.0, 2.0, 0.3, -M_PI / 2, M_PI, &r, 1, 1);
  b.add_scan(3.0, 1.5, 0.0, -M_PI / 2, M_PI, &r, 1, 2);
  MapperParams p;
  p.resolution = 0.5;
  p.range_max = 4.0;
  const GridGeometry g = size_grid(b, p);
  // R = 4.5; mx = 2 + 4.5 = 6.5 -> ceil(13) = 13 -> 28; my = 0.5 + 4.5 = 5 -> 10 -> 22.
  EXPECT_EQ(g.size_x, 28);
  EXPECT_EQ(g.size_y, 22);
  EXPECT_EQ(g.theta_offset, 0.3);
  EXPECT_EQ(g.x0, 1.0);
  EXPECT_EQ(g.y0, 2.0);
}

TEST(SizeGrid, AbsurdExtentIsAClearErrorNotAnAllocation) {
  ScanBatch b;
  float r = 1.0f;
  b.add_scan(0.0, 0.0, 0.0, 0, 0, &r, 1, 1);
  b.add_scan(1e12, -1e12, 0.0, 0, 0, &r, 1, 7);
  MapperParams p;
  try {
    size_grid(b, p);
    FAIL() << "expected an error";
  } catch (const Error &e) {
    EXPECT_EQ(e.code(), ErrorCode::TooLarge);
    EXPECT_NE(std::string(e.what()).find("too large"), std::string::npos) << e.what();
  }
}

TEST(SizeGrid, EmptyBatchIsAnError) {
  ScanBatch b;
  EXPECT_THROW(size_grid(b, MapperParams{}), Error);
}

TEST(StartFrame, RecordsScanZerosPoseAsCarmensFirstUpdate) {
  ScanBatch b;
  float r = 1.0f;
  b.add_scan(1.5, -2.0, 0.4, 0, 0, &r, 1, 1);
  b.add_scan(3.0, 1.0, 0.1, 0, 0, &r, 1, 2);
  GridGeometry g;
  g.size_x = 40;
  g.size_y = 30;
  g.resolution = 0.25;
  g.theta_offset = 0.4;
  const oracle::GridFrame f = start_frame(g, b);
  EXPECT_EQ(f.size_x, 40);
  EXPECT_EQ(f.size_y, 30);
  EXPECT_EQ(f.resolution, 0.25);
  EXPECT_EQ(f.theta_offset, 0.4);
  EXPECT_FALSE(f.first);
  EXPECT_EQ(f.start_x, 1.5 / 0.25);
  EXPECT_EQ(f.start_y, -2.0 / 0.25);
  EXPECT_EQ(f.start_theta, 0.4);
  EXPECT_TRUE(start_frame(g, ScanBatch{}).first);
}

}  // namespace
}  // namespace vasco
