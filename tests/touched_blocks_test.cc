// The blocks of a render's box that its scans reach (vasco_gpu/src/
// touched_blocks.h): each marked square's blocks, clipped to the box, and
// every cell of them once, column by column; nothing else.
#include "touched_blocks.h"

#include <gtest/gtest.h>

#include <set>
#include <utility>
#include <vector>

namespace {

using vasco::TouchedBlocks;
constexpr int kSide = TouchedBlocks::kSide;

vasco::beam_updates::Box box_of(int width, int height) {
  vasco::beam_updates::Box b;
  b.x_lo = 100, b.y_lo = -50;  // runs are box-relative whatever the box's place
  b.x_hi = 100 + width, b.y_hi = -50 + height;
  return b;
}

// Every (x, y) the runs name, each checked to be named once.
std::set<std::pair<int, int>> cells_of(const TouchedBlocks &t) {
  std::set<std::pair<int, int>> cells;
  t.for_each_run([&](int x, int y0, int y1) {
    EXPECT_LT(y0, y1);
    for (int y = y0; y < y1; ++y) EXPECT_TRUE(cells.insert({x, y}).second) << x << "," << y << " named twice";
  });
  return cells;
}

TEST(TouchedBlocks, NothingMarkedNamesNoCell) {
  TouchedBlocks t;
  t.reset(box_of(300, 200));
  EXPECT_TRUE(cells_of(t).empty());
  EXPECT_EQ(t.cells(), 0u);
}

TEST(TouchedBlocks, ASquareMarksTheBlocksItMeetsAndNoOther) {
  const int w = 5 * kSide + 7, h = 3 * kSide + 1;  // partial blocks at the far edges
  TouchedBlocks t;
  t.reset(box_of(w, h));
  t.mark(kSide - 1, kSide, 2 * kSide, 2 * kSide);  // blocks x 0..1, y 2
  const auto cells = cells_of(t);
  for (int x = 0; x < w; ++x)
    for (int y = 0; y < h; ++y) {
      const bool want = x < 2 * kSide && y >= 2 * kSide && y < 3 * kSide;
      ASSERT_EQ(cells.count({x, y}) == 1, want) << x << "," << y;
    }
  EXPECT_EQ(t.cells(), size_t(2 * kSide) * kSide);
}

TEST(TouchedBlocks, SquaresPastTheBoxAreClippedToIt) {
  const int w = 2 * kSide + 3, h = kSide + 5;
  TouchedBlocks t;
  t.reset(box_of(w, h));
  t.mark(-1000, 1000, -1000, 1000);  // the whole box, partial blocks included
  EXPECT_EQ(cells_of(t).size(), size_t(w) * h);
  EXPECT_EQ(t.cells(), size_t(w) * h);
  t.reset(box_of(w, h));
  t.mark(w, w + 10, 0, 5);  // beside the box: nothing
  t.mark(-20, -1, 0, 5);
  EXPECT_EQ(t.cells(), 0u);
}

TEST(TouchedBlocks, ResetForgetsTheMarks) {
  TouchedBlocks t;
  t.reset(box_of(4 * kSide, 4 * kSide));
  t.mark(0, 4 * kSide - 1, 0, 4 * kSide - 1);
  t.reset(box_of(4 * kSide, 4 * kSide));
  t.mark(3 * kSide, 3 * kSide, kSide, kSide);
  const auto cells = cells_of(t);
  EXPECT_EQ(cells.size(), size_t(kSide) * kSide);
  EXPECT_EQ(cells.count({3 * kSide, kSide}), 1u);
}

}  // namespace
