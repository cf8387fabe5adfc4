// CARMEN's evidence-grid C API (carmen/egrid.h) on small cases worked out by
// hand from DESIGN §2.
#include "carmen/egrid.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include <type_traits>

#include <cmath>

namespace {

constexpr float kFree1 = 0.44999999f;  // one p = 0.45 update from unknown, prior 0.5
constexpr float kOcc1 = 0.55000001f;   // one p = 0.55 update (carmen-formats §4.3 worked check)

// Two p = 0.45 updates from unknown, written out from the formula.
float free_twice() {
  const float first = kFree1;
  double t = (1 - 0.5) / 0.5;
  t = t * 0.45;
  t = t / (1 - 0.45);
  t = t * (double)first;
  t = t / (double)(1.0f - first);
  return (float)(1 - 1 / (1 + t));
}

class EgridApi : public ::testing::Test {
 protected:
  void SetUp() override {
    carmen_mapper_initialize_evidence_grid(&g, 20, 20, 1.0, 0.0, 0.5, 0.55, 0.45, 0.95, 5.0, 10.0,
                                           0.0);
    ASSERT_NE(g.prob, nullptr);
  }
  void TearDown() override { carmen_mapper_free_evidence_grid(&g); }
  int known() const {
    int n = 0;
    for (int x = 0; x < g.size_x; ++x)
      for (int y = 0; y < g.size_y; ++y) n += g.prob[x][y] != -1.0f;
    return n;
  }
  evidence_grid g;
};

TEST_F(EgridApi, InitialisesUnknownCellsAndTheDistanceTable) {
  EXPECT_EQ(known(), 0);
  EXPECT_EQ(g.distance_table_size, 10);
  ASSERT_NE(g.distance_table, nullptr);
  EXPECT_EQ(g.distance_table[3][4], 5.0);
  EXPECT_EQ(g.first, 1);
}

TEST_F(EgridApi, OneBeamAlongX) {
  float r = 3.0f;
  carmen_mapper_update_evidence_grid(&g, 0.0, 0.0, 0.0, 1, &r, 0.0, 0.0);
  // Start cell floor(20/2.0) = 10; end cell (int)(10 + 3) = 13. Cells at
  // distance 0, 1, 2 are free (d < r), the cell at distance 3 is the hit.
  EXPECT_EQ(g.prob[10][10], kFree1);
  EXPECT_EQ(g.prob[11][10], kFree1);
  EXPECT_EQ(g.prob[12][10], kFree1);
  EXPECT_EQ(g.prob[13][10], kOcc1);
  EXPECT_EQ(known(), 4);
  EXPECT_EQ(g.first, 0);
}

TEST_F(EgridApi, SkippedBeamsStillAdvanceTheAngle) {
  // Beams at 0, pi/2 (range 60: skipped, clears nothing) and pi.
  float r[3] = {2.0f, 60.0f, 2.0f};
  carmen_mapper_update_evidence_grid(&g, 0.0, 0.0, 0.0, 3, r, M_PI / 2, 0.0);
  EXPECT_EQ(g.prob[10][10], free_twice());  // the start cell is updated by every used beam
  EXPECT_EQ(g.prob[11][10], kFree1);
  EXPECT_EQ(g.prob[12][10], kOcc1);
  EXPECT_EQ(g.prob[9][10], kFree1);
  EXPECT_EQ(g.prob[8][10], kOcc1);
  EXPECT_EQ(g.prob[10][11], -1.0f);
  EXPECT_EQ(known(), 5);
}

TEST_F(EgridApi, NanAndInfRangesAreSkippedNegativeRangesAreNot) {
  float r[3] = {NAN, INFINITY, -1.0f};
  carmen_mapper_update_evidence_grid(&g, 0.0, 0.0, 0.0, 3, r, 0.0, 0.0);
  // Only the negative beam is used: r + wall = -1, end cell (int)(10 - 1) = 9;
  // every cell has d >= r, so both are occupied.
  EXPECT_EQ(g.prob[10][10], kOcc1);
  EXPECT_EQ(g.prob[9][10], kOcc1);
  EXPECT_EQ(known(), 2);
}

TEST_F(EgridApi, MinusInfinityRangeEndsQuickly) {
  // -inf < 50, so the beam is used; its end cell is INT_MIN. The walk must
  // terminate (at the distance-table bound), not run 2^31 cells.
  float r = -INFINITY;
  carmen_mapper_update_evidence_grid(&g, 0.0, 0.0, 0.0, 1, &r, 0.0, 0.0);
  EXPECT_GE(known(), 1);
}

TEST_F(EgridApi, GeneralUpdateUsesPerBeamAngles) {
  float r[2] = {2.0f, 2.0f};
  float a[2] = {0.0f, static_cast<float>(M_PI)};
  carmen_mapper_update_evidence_grid_general(&g, 0.0, 0.0, 0.0, 2, r, a, 0.0, 0.0);
  EXPECT_EQ(g.prob[12][10], kOcc1);
  // (float)pi is a little above pi, so sin is about -8.7e-8 and the end cell's
  // y is (int)(10 - 1.7e-7) = 9: truncation, not rounding. The walk
  // (10,10) -> (8,9) visits (9,10) (d = 1 < 2: free) and (8,9) (d = sqrt 5: hit).
  EXPECT_EQ(g.prob[9][10], kFree1);
  EXPECT_EQ(g.prob[8][9], kOcc1);
  EXPECT_EQ(g.prob[8][10], -1.0f);
  EXPECT_EQ(g.prob[10][10], free_twice());
}

TEST_F(EgridApi, LaterScansAreRelativeToTheFirstPose) {
  float r = 1.0f;
  carmen_mapper_update_evidence_grid(&g, 100.0, 50.0, 0.0, 1, &r, 0.0, 0.0);
  carmen_mapper_update_evidence_grid(&g, 103.0, 52.0, 0.0, 1, &r, 0.0, 0.0);
  EXPECT_EQ(g.prob[10][10], kFree1);
  EXPECT_EQ(g.prob[11][10], kOcc1);
  EXPECT_EQ(g.prob[13][12], kFree1);
  EXPECT_EQ(g.prob[14][12], kOcc1);
}

TEST_F(EgridApi, ABadScanIsRefusedWithAMessageAndChangesNothing) {
  float r[3] = {1.0f, 2.0f, 3.0f};
  carmen_mapper_update_evidence_grid(&g, 10, 10, 0, 3, r, 0.1, -0.1);
  const int before = known();
  ASSERT_GT(before, 0);
  struct Case {
    int n;
    float *ranges;
    float *angles;
    bool general;
    const char *message;
  } cases[] = {
      {-1, r, nullptr, false, "carmen_mapper_update_evidence_grid: -1 readings: scan ignored\n"},
      {3, nullptr, nullptr, false, "carmen_mapper_update_evidence_grid: 3 readings and laser_range NULL: scan ignored\n"},
      {-5, r, r, true, "carmen_mapper_update_evidence_grid_general: -5 readings: scan ignored\n"},
      {3, r, nullptr, true, "carmen_mapper_update_evidence_grid_general: 3 readings and laser_angle NULL: scan ignored\n"},
  };
  for (const Case &c : cases) {
    testing::internal::CaptureStderr();
    if (c.general)
      carmen_mapper_update_evidence_grid_general(&g, 12, 10, 0, c.n, c.ranges, c.angles, 0.1, -0.1);
    else
      carmen_mapper_update_evidence_grid(&g, 12, 10, 0, c.n, c.ranges, 0.1, -0.1);
    EXPECT_EQ(testing::internal::GetCapturedStderr(), c.message);
    EXPECT_EQ(known(), before);
  }
  testing::internal::CaptureStderr();
  carmen_mapper_update_evidence_grid(nullptr, 0, 0, 0, 3, r, 0.1, 0);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "carmen_mapper_update_evidence_grid: grid is NULL: scan ignored\n");
}

TEST_F(EgridApi, ClearSetsThePrior) {
  carmen_mapper_clear_evidence_grid(&g);
  EXPECT_EQ(g.prob[0][0], 0.5f);
  EXPECT_EQ(g.prob[19][19], 0.5f);
}

TEST_F(EgridApi, FinishDownsamplesAndCrops) {
  float r = 3.0f;
  carmen_mapper_update_evidence_grid(&g, 0.0, 0.0, 0.0, 1, &r, 0.0, 0.0);
  carmen_mapper_finish_evidence_grid(&g, 2, 0);
  // Blocks of 2: (5,5) holds cells x 10..11, y 10..11 -> two free cells;
  // (6,5) holds x 12..13 -> one free, one occupied. Known blocks span x 5..6,
  // y 5..5; the size is max - min: 1 x 0.
  EXPECT_EQ(g.size_x, 1);
  EXPECT_EQ(g.size_y, 0);
  EXPECT_EQ(g.resolution, 2.0);
}

// A run that mapped nothing (an empty or scan-less log): CARMEN's finish
// sizes the map max - min = 4 border + 1 - n blocks, negative for a grid of
// more blocks, and dies "Out of memory" before its caller writes a map. Ours
// stops there too, saying why, so that no half-written map file follows,
// with carmen_die's status: exit(-1), 255 to the shell that checks it.
TEST_F(EgridApi, FinishingAGridThatMappedNothingStopsAsCarmenDoes) {
  EXPECT_EQ(vasco_egrid_finish_would_stop(&g, 1, 2), 1);
  EXPECT_EQ(vasco_egrid_finish_would_stop(&g, 1, 5), 0);  // 20 blocks <= 4 x 5 + 1: CARMEN finishes it
  EXPECT_EQ(vasco_egrid_finish_would_stop(nullptr, 1, 2), 0);
  EXPECT_EXIT(carmen_mapper_finish_evidence_grid(&g, 1, 2), ::testing::ExitedWithCode(255),
              "no cell of the 20 x 20 grid was updated");
}

TEST_F(EgridApi, ASmallGridThatMappedNothingFinishesAsCarmensDoes) {
  // 20 blocks <= 4 x 5 + 1: CARMEN's bounds (14, 5) move out by the border
  // to (9, 10): a 1 x 1 map (4 x 5 + 1 - 20), its cell unknown.
  carmen_mapper_finish_evidence_grid(&g, 1, 5);
  EXPECT_EQ(vasco_egrid_finish_would_stop(&g, 1, 5), 0);
  EXPECT_EQ(g.size_x, 1);
  EXPECT_EQ(g.size_y, 1);
  EXPECT_EQ(g.prob[0][0], -1.0f);
}

// CARMEN 0.7.4's prototypes exactly (DESIGN §2): a CARMEN program that keeps
// these functions in pointers of CARMEN's types compiles against ours.
static_assert(std::is_same<decltype(&carmen_mapper_initialize_evidence_grid),
                           int (*)(evidence_grid *, int, int, double, double, double, double, double,
                                   double, double, double, double)>::value,
              "carmen_mapper_initialize_evidence_grid: CARMEN's prototype");
static_assert(std::is_same<decltype(&carmen_mapper_update_evidence_grid_general),
                           void (*)(evidence_grid *, double, double, double, int, float *, float *, double,
                                    double)>::value,
              "carmen_mapper_update_evidence_grid_general: CARMEN's prototype");
static_assert(std::is_same<decltype(&carmen_mapper_update_evidence_grid),
                           void (*)(evidence_grid *, double, double, double, int, float *, double, double)>::value,
              "carmen_mapper_update_evidence_grid: CARMEN's prototype");
#ifndef EGRID_H
#error "egrid.h must define CARMEN's guard EGRID_H"
#endif

TEST(EgridApiPrototypes, InitializeReturnsZero) {
  evidence_grid g;
  EXPECT_EQ(carmen_mapper_initialize_evidence_grid(&g, 10, 10, 1, 0, 0.5, 0.55, 0.45, 0.95, 5, 10, 0), 0);
  carmen_mapper_free_evidence_grid(&g);
}

TEST(EgridApiErrors, NullAndBadSizesDoNotCrash) {
  EXPECT_EQ(carmen_mapper_initialize_evidence_grid(nullptr, 10, 10, 1, 0, 0.5, 0.55, 0.45, 0.95, 5, 10, 0), -1);
  evidence_grid g;
  EXPECT_EQ(carmen_mapper_initialize_evidence_grid(&g, -5, 10, 1, 0, 0.5, 0.55, 0.45, 0.95, 5, 10, 0), -1);
  EXPECT_EQ(g.prob, nullptr);
  float r = 1;
  carmen_mapper_update_evidence_grid(&g, 0, 0, 0, 1, &r, 0, 0);  // no-op
  carmen_mapper_finish_evidence_grid(&g, 2, 1);                  // no-op
  carmen_mapper_free_evidence_grid(&g);
  carmen_mapper_update_evidence_grid(nullptr, 0, 0, 0, 1, &r, 0, 0);
}

}  // namespace
