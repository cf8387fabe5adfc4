// Tests of planar poses along a trajectory (vasco_gpu/pose_series.h): the
// interpolation written once for pose files, bags' pose topics and the live
// node's Path. Expected values are worked out by hand here.
#include "vasco_gpu/internal/se2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace {

using vasco::Pose2;
using vasco::PoseSeriesView;
using vasco::SeriesPlace;

constexpr double kPi = 3.14159265358979323846;

TEST(PoseSeries, AngleDifferenceTakesTheShorterWayRound) {
  EXPECT_DOUBLE_EQ(vasco::angle_difference(0.0, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(vasco::angle_difference(1.0, 0.0), -1.0);
  // 3 -> -3 is 0.283 rad forwards across +-pi, not 6 back
  EXPECT_NEAR(vasco::angle_difference(3.0, -3.0), 2 * kPi - 6.0, 1e-15);
  EXPECT_NEAR(vasco::angle_difference(-3.0, 3.0), 6.0 - 2 * kPi, 1e-15);
  // a difference already in range comes back bit for bit
  EXPECT_EQ(vasco::angle_difference(0.25, 0.25 + 0.1), (0.25 + 0.1) - 0.25);
  // half a turn is -pi ([-pi, pi))
  EXPECT_DOUBLE_EQ(vasco::angle_difference(0.0, kPi), -kPi);
}

TEST(PoseSeries, PoseBetweenIsLinearAndTurnsTheShortWay) {
  const Pose2 a{1.0, 2.0, 3.0}, b{3.0, -2.0, -3.0};
  const Pose2 start = vasco::pose_between(a, b, 0.0);
  EXPECT_EQ(start.x, 1.0);
  EXPECT_EQ(start.y, 2.0);
  EXPECT_EQ(start.theta, 3.0);
  const Pose2 mid = vasco::pose_between(a, b, 0.5);
  EXPECT_DOUBLE_EQ(mid.x, 2.0);
  EXPECT_DOUBLE_EQ(mid.y, 0.0);
  EXPECT_NEAR(mid.theta, 3.0 + (2 * kPi - 6.0) / 2, 1e-15);  // past +pi, unwrapped
}

struct Series {
  std::vector<int64_t> stamps{100, 200, 1000};
  std::vector<Pose2> poses{{0, 0, 0}, {10, 20, 1}, {0, 0, 0}};
  PoseSeriesView view() const { return {stamps.data(), poses.data(), stamps.size()}; }
};

TEST(PoseSeries, PoseAtStampPlacesEachStamp) {
  const Series s;
  Pose2 p{-1, -1, -1};
  EXPECT_EQ(vasco::pose_at_stamp(s.view(), 99, 500, p), SeriesPlace::Outside);
  EXPECT_EQ(vasco::pose_at_stamp(s.view(), 1001, 500, p), SeriesPlace::Outside);
  EXPECT_EQ(p.x, -1);  // untouched
  ASSERT_EQ(vasco::pose_at_stamp(s.view(), 200, 500, p), SeriesPlace::Exact);
  EXPECT_EQ(p.x, 10);
  EXPECT_EQ(p.theta, 1);
  ASSERT_EQ(vasco::pose_at_stamp(s.view(), 125, 500, p), SeriesPlace::Between);
  EXPECT_DOUBLE_EQ(p.x, 2.5);  // a quarter of the way from 100 to 200
  EXPECT_DOUBLE_EQ(p.y, 5.0);
  EXPECT_DOUBLE_EQ(p.theta, 0.25);
  p = {-1, -1, -1};
  EXPECT_EQ(vasco::pose_at_stamp(s.view(), 600, 500, p), SeriesPlace::InGap);  // 200..1000: 800 apart
  EXPECT_EQ(p.x, -1);
  EXPECT_EQ(vasco::pose_at_stamp(s.view(), 600, 800, p), SeriesPlace::Between);  // the limit included
  EXPECT_DOUBLE_EQ(p.x, 5.0);
  EXPECT_EQ(vasco::pose_at_stamp(s.view(), 1000, 0, p), SeriesPlace::Exact);  // no gap: stamps only
}

TEST(PoseSeries, FractionsComeFromTheIntegerStamps) {
  // stamps near 2^62 ns: as doubles they would be 1024 ns apart at best; as integers the
  // fraction is exact
  const int64_t t0 = int64_t(1) << 62;
  const std::vector<int64_t> stamps{t0, t0 + 4};
  const std::vector<Pose2> poses{{0, 0, 0}, {4, 0, 0}};
  Pose2 p;
  ASSERT_EQ(vasco::pose_at_stamp({stamps.data(), poses.data(), 2}, t0 + 1, 10, p), SeriesPlace::Between);
  EXPECT_EQ(p.x, 1.0);
}

TEST(PoseSeries, SortSeriesKeepsTheLastSampleOfAStamp) {
  std::vector<int64_t> stamps{30, 10, 20, 10, 30};
  std::vector<Pose2> poses{{3, 0, 0}, {1, 0, 0}, {2, 0, 0}, {1.5, 0, 0}, {3.5, 0, 0}};
  vasco::sort_series(stamps, poses);
  ASSERT_EQ(stamps, (std::vector<int64_t>{10, 20, 30}));
  EXPECT_EQ(poses[0].x, 1.5);
  EXPECT_EQ(poses[1].x, 2.0);
  EXPECT_EQ(poses[2].x, 3.5);
  EXPECT_TRUE(vasco::strictly_ascending(stamps.data(), stamps.size()));
  const int64_t repeated[] = {1, 2, 2};
  EXPECT_FALSE(vasco::strictly_ascending(repeated, 3));
}

}  // namespace
