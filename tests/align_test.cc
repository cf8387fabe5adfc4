// align_maps on drawn maps: a floor plan drawn twice, the second time in a
// frame moved by a transform the test knows, must be found again; a plan
// with a symmetry must be called ambiguous, two different plans no overlap;
// empty and degenerate maps are refused without throwing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "test_seed.h"
#include "align_test_support.h"
#include "vasco_gpu/align.h"
#include "vasco_gpu/error.h"

namespace {

using vasco::testing_support::distance_to;
using vasco::testing_support::Segment;

using vasco::AlignMap;
using vasco::AlignOptions;
using vasco::AlignResult;
using vasco::AlignVerdict;

constexpr double kPi = 3.14159265358979323846;

// A floor plan: wall segments, and the rectangle inside which a robot saw
// free space (outside it nothing is known).
struct Plan {
  std::vector<Segment> walls;
  double x0, y0, x1, y1;
};

// What the plan says at world (x, y): a wall 0.1 m thick, free inside, unknown outside.
float plan_at(const Plan &plan, double x, double y) {
  for (const Segment &s : plan.walls)
    if (distance_to(s, x, y) <= 0.05) return 0.9f;
  const bool inside = x >= plan.x0 && x <= plan.x1 && y >= plan.y0 && y <= plan.y1;
  return inside ? 0.05f : -1.0f;
}

struct Pose {
  double x, y, theta;
};

// The plan as a robot in frame `frame` maps it: a map in frame coordinates
// q, whose cell shows the plan at T(q) = R(theta) q + (x, y), over the part
// of the plan in the world box [wx0, wx1] x [wy0, wy1].
AlignMap draw(const Plan &plan, const Pose &frame, double res, double wx0, double wy0, double wx1, double wy1) {
  // The box's corners in frame coordinates bound the map.
  const double c = std::cos(frame.theta), s = std::sin(frame.theta);
  double lo_x = 1e300, lo_y = 1e300, hi_x = -1e300, hi_y = -1e300;
  for (double wx : {wx0, wx1})
    for (double wy : {wy0, wy1}) {
      const double dx = wx - frame.x, dy = wy - frame.y;
      const double qx = c * dx + s * dy, qy = -s * dx + c * dy;
      lo_x = std::min(lo_x, qx), hi_x = std::max(hi_x, qx);
      lo_y = std::min(lo_y, qy), hi_y = std::max(hi_y, qy);
    }
  AlignMap m;
  m.resolution = res;
  m.origin_x = lo_x;
  m.origin_y = lo_y;
  m.size_x = static_cast<int>(std::ceil((hi_x - lo_x) / res));
  m.size_y = static_cast<int>(std::ceil((hi_y - lo_y) / res));
  m.cells.assign(static_cast<size_t>(m.size_x) * m.size_y, -1.0f);
  for (int x = 0; x < m.size_x; ++x)
    for (int y = 0; y < m.size_y; ++y) {
      const double qx = lo_x + (x + 0.5) * res, qy = lo_y + (y + 0.5) * res;
      const double wx = frame.x + c * qx - s * qy, wy = frame.y + s * qx + c * qy;
      if (wx >= wx0 && wx <= wx1 && wy >= wy0 && wy <= wy1) m.cells[static_cast<size_t>(x) * m.size_y + y] = plan_at(plan, wx, wy);
    }
  return m;
}

// An office floor without symmetry: outer walls, rooms of unequal sizes,
// doors at different places.
Plan office() {
  Plan p{{}, 0, 0, 24, 14};
  auto wall = [&](double x0, double y0, double x1, double y1) { p.walls.push_back({x0, y0, x1, y1}); };
  wall(0, 0, 24, 0), wall(24, 0, 24, 14), wall(24, 14, 0, 14), wall(0, 14, 0, 0);
  wall(0, 6, 3, 6), wall(4.2, 6, 11, 6), wall(12.5, 6, 24, 6);        // corridor's south side, two doors
  wall(0, 8.5, 7, 8.5), wall(8, 8.5, 17, 8.5), wall(18.2, 8.5, 24, 8.5);  // north side
  wall(5, 0, 5, 6), wall(13, 0, 13, 4.5), wall(18.5, 2, 18.5, 6);      // rooms to the south
  wall(9, 8.5, 9, 14), wall(15.5, 11, 15.5, 14), wall(20, 8.5, 20, 12);  // to the north
  wall(2, 10, 4, 12), wall(21, 2.5, 22.5, 2.5);                          // a cupboard, a desk
  return p;
}

double angle_error(double a, double b) { return std::abs(std::remainder(a - b, 2 * kPi)); }

void expect_found(const AlignResult &r, const Pose &truth, double cell, const std::string &what) {
  EXPECT_EQ(r.verdict, AlignVerdict::Aligned) << what << ": " << r.reason;
  EXPECT_LE(std::abs(r.best.x - truth.x), cell) << what;
  EXPECT_LE(std::abs(r.best.y - truth.y), cell) << what;
  EXPECT_LE(angle_error(r.best.theta, truth.theta), 0.5 * kPi / 180) << what;
  std::cout << what << ": found (" << r.best.x << ", " << r.best.y << ", " << r.best.theta << ") score "
            << r.best.score << " second " << r.second.score << " overlap " << r.overlap << " truth (" << truth.x
            << ", " << truth.y << ", " << truth.theta << ")\n";
}

// The same plan drawn in the world frame and in a frame moved by T: the
// moving map's frame goes into the reference's by T itself.
TEST(AlignMaps, FindsAKnownTransformOfADrawnPlan) {
  std::mt19937 rng(vasco::testing_support::test_seed(58));
  std::uniform_real_distribution<double> shift(-30, 30), turn(-kPi, kPi);
  const Plan plan = office();
  const AlignMap reference = draw(plan, {0, 0, 0}, 0.05, 0, 0, 24, 14);
  for (int trial = 0; trial < 4; ++trial) {
    const Pose truth{shift(rng), shift(rng), turn(rng)};
    const AlignMap moving = draw(plan, truth, 0.05, 6, 0, 24, 14);  // the east three quarters
    AlignOptions options;
    options.threads = 2;
    expect_found(vasco::align_maps(reference, moving, options), truth, 0.1, "trial " + std::to_string(trial));
  }
}

// Maps at another cell than the matching one: a coarser moving map is
// sampled, a finer reference max-pooled.
TEST(AlignMaps, MatchesMapsOfDifferentCells) {
  const Plan plan = office();
  const Pose truth{-3.2, 7.7, 2.4};
  const AlignMap reference = draw(plan, {0, 0, 0}, 0.025, 0, 0, 24, 14);
  const AlignMap moving = draw(plan, truth, 0.1, 4, 2, 24, 12);
  expect_found(vasco::align_maps(reference, moving, {}), truth, 0.1, "0.025 m and 0.1 m");
}

// A hint restricts the search to its neighbourhood: near the truth it finds
// it; far from it, not.
TEST(AlignMaps, SearchesOnlyNearAHint) {
  const Plan plan = office();
  const Pose truth{5, -2, 0.7};
  const AlignMap reference = draw(plan, {0, 0, 0}, 0.1, 0, 0, 24, 14);
  const AlignMap moving = draw(plan, truth, 0.1, 0, 0, 24, 14);
  AlignOptions near;
  near.hint = vasco::AlignHint{5.4, -2.3, 0.75, 1.0, 0.1};
  const AlignResult r = vasco::align_maps(reference, moving, near);
  expect_found(r, truth, 0.1, "near the hint");
  EXPECT_LT(r.rotations, 200);
  AlignOptions far = near;
  far.hint = vasco::AlignHint{-5, 3, -1.0, 0.5, 0.05};
  const AlignResult wrong = vasco::align_maps(reference, moving, far);
  EXPECT_NE(wrong.verdict, AlignVerdict::Aligned);
  EXPECT_GT(std::abs(wrong.best.x - truth.x), 1.0);
}

// A plain rectangular room looks the same turned by half a turn: two
// candidates score alike, and the result says so.
TEST(AlignMaps, CallsASymmetricRoomAmbiguous) {
  Plan room{{{0, 0, 9, 0}, {9, 0, 9, 5}, {9, 5, 0, 5}, {0, 5, 0, 0}}, 0, 0, 9, 5};
  const AlignMap reference = draw(room, {0, 0, 0}, 0.1, -0.5, -0.5, 9.5, 5.5);
  const AlignMap moving = draw(room, {2, 1, 0.3}, 0.1, -0.5, -0.5, 9.5, 5.5);
  const AlignResult r = vasco::align_maps(reference, moving, {});
  EXPECT_EQ(r.verdict, AlignVerdict::Ambiguous) << r.reason;
  EXPECT_TRUE(r.has_second);
  EXPECT_NEAR(angle_error(r.best.theta, r.second.theta), kPi, 0.05);
}

// A corridor with a door every 3 m: shifted by one door it looks the same.
TEST(AlignMaps, CallsAPeriodicCorridorAmbiguous) {
  Plan corridor{{}, 0, 0, 30, 2};
  for (double x = 0; x < 30; x += 3) {
    corridor.walls.push_back({x, 0, x + 2.2, 0});
    corridor.walls.push_back({x + 0.8, 2, x + 3, 2});
  }
  const AlignMap reference = draw(corridor, {0, 0, 0}, 0.1, 0, -0.5, 30, 2.5);
  const AlignMap moving = draw(corridor, {1, 4, -0.4}, 0.1, 6, -0.5, 24, 2.5);
  const AlignResult r = vasco::align_maps(reference, moving, {});
  EXPECT_EQ(r.verdict, AlignVerdict::Ambiguous) << r.reason;
}

// Two different plans: whatever the best candidate, it is no alignment.
TEST(AlignMaps, RefusesTwoDifferentPlans) {
  Plan other{{}, 0, 0, 20, 20};
  for (double v = 0; v <= 20; v += 5) {
    other.walls.push_back({v, 0, v, 20 - v / 2});
    other.walls.push_back({0, v, 20 - v / 3, v});
  }
  const AlignMap reference = draw(office(), {0, 0, 0}, 0.1, 0, 0, 24, 14);
  const AlignMap moving = draw(other, {3, 3, 1}, 0.1, 0, 0, 20, 20);
  const AlignResult r = vasco::align_maps(reference, moving, {});
  EXPECT_NE(r.verdict, AlignVerdict::Aligned) << "score " << r.best.score;
}

TEST(AlignMaps, RefusesEmptyAndDegenerateMapsWithoutThrowing) {
  const AlignMap plan = draw(office(), {0, 0, 0}, 0.1, 0, 0, 24, 14);
  AlignMap empty;
  empty.resolution = 0.1;
  AlignMap unknown = plan;
  std::fill(unknown.cells.begin(), unknown.cells.end(), -1.0f);
  AlignMap free_only = plan;
  std::fill(free_only.cells.begin(), free_only.cells.end(), 0.1f);
  AlignMap one_wall = free_only;
  one_wall.cells[100] = 1.0f;
  for (const AlignMap *m : {&empty, &unknown, &free_only, &one_wall}) {
    for (const bool as_moving : {false, true}) {
      const AlignResult r = as_moving ? vasco::align_maps(plan, *m, {}) : vasco::align_maps(*m, plan, {});
      EXPECT_EQ(r.verdict, AlignVerdict::NoOverlap);
      EXPECT_FALSE(r.reason.empty());
    }
  }
}

TEST(AlignMaps, RejectsBadOptionsAndMalformedMaps) {
  const AlignMap plan = draw(office(), {0, 0, 0}, 0.1, 0, 0, 24, 14);
  auto code_of = [](auto call) -> std::optional<vasco::ErrorCode> {
    try {
      call();
    } catch (const vasco::Error &e) {
      return e.code();
    }
    return std::nullopt;
  };
  AlignOptions bad;
  bad.match_resolution = 0;
  EXPECT_EQ(code_of([&] { vasco::align_maps(plan, plan, bad); }), vasco::ErrorCode::Usage);
  bad = {};
  bad.threads = -1;
  EXPECT_EQ(code_of([&] { vasco::align_maps(plan, plan, bad); }), vasco::ErrorCode::Usage);
  bad = {};
  bad.hint = vasco::AlignHint{0, 0, 0, -1, 0.1};
  EXPECT_EQ(code_of([&] { vasco::align_maps(plan, plan, bad); }), vasco::ErrorCode::Usage);
  AlignMap short_cells = plan;
  short_cells.cells.pop_back();
  EXPECT_EQ(code_of([&] { vasco::align_maps(plan, short_cells, {}); }), vasco::ErrorCode::BadInput);
  AlignMap nan_origin = plan;
  nan_origin.origin_x = NAN;
  EXPECT_EQ(code_of([&] { vasco::align_maps(nan_origin, plan, {}); }), vasco::ErrorCode::BadInput);
}

}  // namespace
