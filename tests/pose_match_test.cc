// Tests of matching a pose file's poses to a log's scans
// (vasco_gpu/pipeline/pose_match.h). Expected values are worked out by hand
// here, not taken from the code under test.
#include "vasco_gpu/pipeline/pose_match.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "carmen_compat/error.h"
#include "pose_test_support.h"
#include "temp_dir.h"

namespace {

using carmen::ErrorCode;
using pose_test::error_of;
using pose_test::kPi;
using pose_test::same_bits;
using pose_test::write_file;
using vasco::Pose2;
using vasco::PoseFile;
using vasco::PoseFileFormat;
using vasco::PoseMatch;
using vasco::PoseMatching;
using vasco::PoseMatchOptions;
using vasco::StampedPose;

// A pose file made in memory, for the matching tests.
PoseFile stamped_file(const std::vector<std::pair<double, Pose2>> &poses, const std::string &path = "traj.txt") {
  PoseFile f;
  f.path = path;
  f.format = PoseFileFormat::Tum;
  long line = 1;
  for (const auto &p : poses) {
    StampedPose s;
    s.stamp = p.first;
    s.line = line++;
    s.pose = p.second;
    f.poses.push_back(s);
  }
  return f;
}

PoseFile g2o_file(const std::vector<std::pair<long, Pose2>> &vertices, const std::string &path = "graph.g2o") {
  PoseFile f;
  f.path = path;
  f.format = PoseFileFormat::G2o;
  long line = 10;
  for (const auto &v : vertices) {
    StampedPose s;
    s.stamp = std::numeric_limits<double>::quiet_NaN();
    s.id = v.first;
    s.line = line++;
    s.pose = v.second;
    f.poses.push_back(s);
  }
  return f;
}

PoseMatchOptions matching(PoseMatching how) {
  PoseMatchOptions o;
  o.matching = how;
  return o;
}

TEST(PoseMatchNames, Matchings) {
  EXPECT_EQ(vasco::pose_matching_from_name("auto"), PoseMatching::Auto);
  EXPECT_EQ(vasco::pose_matching_from_name("order"), PoseMatching::Order);
  EXPECT_EQ(vasco::pose_matching_from_name("id"), PoseMatching::Id);
  EXPECT_EQ(vasco::pose_matching_from_name("time"), PoseMatching::Timestamp);
  const std::string what = error_of([] { vasco::pose_matching_from_name("timestamp"); }, ErrorCode::Usage);
  EXPECT_CONTAINS(what, "'timestamp'");
  EXPECT_CONTAINS(what, "expected one of auto, order, id, time");
}

// ---------------------------------------------------------------------------
// Matching.

TEST(PoseMatch, OrderCopiesPoseIToScanI) {
  const PoseFile f = g2o_file({{5, {1, 2, 3}}, {2, {4, 5, 6}}, {9, {7, 8, 9}}});
  const PoseMatch m = vasco::match_poses(f, 3, {}, "intel.log", {}, PoseMatchOptions{});  // Auto: g2o -> Order
  EXPECT_EQ(m.used, PoseMatching::Order);
  ASSERT_EQ(m.pose.size(), 3u);
  EXPECT_EQ(m.pose[1].x, 4);
  EXPECT_EQ(m.pose[1].y, 5);
  EXPECT_EQ(m.pose[1].theta, 6);
  EXPECT_EQ(m.pose[2].x, 7);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({1, 1, 1}));
  EXPECT_EQ(m.unmatched, 0u);
  // A stamped file matched in order on request.
  const PoseFile t = stamped_file({{1, {1, 1, 1}}, {2, {2, 2, 2}}});
  const PoseMatch mt = vasco::match_poses(t, 2, {}, "", {}, matching(PoseMatching::Order));
  EXPECT_EQ(mt.used, PoseMatching::Order);
  EXPECT_EQ(mt.pose[1].x, 2);
}

TEST(PoseMatch, OrderCountsMustAgree) {
  const PoseFile f = g2o_file({{0, {}}, {1, {}}, {2, {}}});
  for (size_t scans : {2u, 4u}) {
    PoseMatchOptions o = matching(PoseMatching::Order);
    o.skip_unmatched = true;  // no help: the counts must agree
    const std::string what =
        error_of([&] { vasco::match_poses(f, scans, {}, "intel.log", {}, o); }, ErrorCode::BadInput);
    EXPECT_CONTAINS(what, "graph.g2o: 3 poses but " + std::to_string(scans) + " scans in intel.log");
  }
}

TEST(PoseMatch, IdIdentityAndIdMap) {
  const PoseFile f = g2o_file({{2, {2, 0, 0}}, {0, {0, 0, 0}}, {1, {1, 0, 0}}});
  PoseMatch m = vasco::match_poses(f, 3, {}, "intel.log", {}, matching(PoseMatching::Id));
  EXPECT_EQ(m.used, PoseMatching::Id);
  for (int s = 0; s < 3; ++s) EXPECT_EQ(m.pose[s].x, s);
  PoseMatchOptions o = matching(PoseMatching::Id);
  o.id_map = {{2, 10}, {0, 20}, {1, 0}};
  o.skip_unmatched = true;  // scans 1..9 and 11..19 get no vertex
  m = vasco::match_poses(f, 21, {}, "intel.log", {}, o);
  EXPECT_EQ(m.pose[10].x, 2);
  EXPECT_EQ(m.pose[20].x, 0);
  EXPECT_EQ(m.pose[0].x, 1);
  EXPECT_EQ(m.unmatched, 18u);
  EXPECT_EQ(m.matched[10] + m.matched[20] + m.matched[0], 3);
}

TEST(PoseMatch, IdErrors) {
  const PoseFile f = g2o_file({{0, {}}, {1, {}}, {7, {}}});  // lines 10, 11, 12
  const auto id_error = [&](size_t scans, const PoseMatchOptions &o, const std::vector<long> &lines = {}) {
    return error_of([&] { vasco::match_poses(f, scans, {}, "intel.log", lines, o); }, ErrorCode::BadInput);
  };
  PoseMatchOptions o = matching(PoseMatching::Id);
  std::string what = id_error(5, o);
  EXPECT_CONTAINS(what, "graph.g2o:12: vertex id 7 is outside the 5 scans in intel.log (0 to 4)");
  o.id_map = {{0, 0}, {1, 1}, {7, 9}};
  what = id_error(5, o);
  EXPECT_CONTAINS(what, "graph.g2o:12: vertex id 7 (mapped to scan 9) is outside");
  o.id_map = {{0, 0}, {1, 1}};
  what = id_error(5, o);
  EXPECT_CONTAINS(what, "graph.g2o:12: vertex id 7 is not in the id map");
  o.id_map = {{0, 0}, {1, 3}, {7, 3}};
  what = id_error(5, o);
  EXPECT_CONTAINS(what, "graph.g2o:12: vertex id 7 and vertex id 1 (line 11) are both for scan 3");
  o.id_map = {{0, 0}, {1, 3}, {7, 4}};  // scans 1 and 2 get no vertex
  what = id_error(5, o, {100, 101, 102, 103, 104});
  EXPECT_CONTAINS(what, "graph.g2o: no vertex for intel.log line 101 (scan 1) (2 of 5 scans in intel.log have none)");
  o.skip_unmatched = true;
  const PoseMatch m = vasco::match_poses(f, 5, {}, "intel.log", {}, o);
  EXPECT_EQ(m.unmatched, 2u);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({1, 0, 0, 1, 1}));
  // Ids belong to g2o files.
  const PoseFile t = stamped_file({{1, {}}});
  what = error_of([&] { vasco::match_poses(t, 1, {1.0}, "", {}, matching(PoseMatching::Id)); }, ErrorCode::Usage);
  EXPECT_CONTAINS(what, "traj.txt: a tum file has no vertex ids");
}


// Stamps 10, 11, 13, with poses whose values are exactly representable.
PoseFile three_stamps() {
  return stamped_file({{10, {1, 10, 0}}, {11, {3, 20, 1}}, {13, {0.1, 1.0 / 3, -2.0 / 3}}});
}

TEST(PoseMatch, TimestampExactStampIsThePoseBitForBit) {
  const PoseFile f = three_stamps();
  const PoseMatch m = vasco::match_poses(f, 2, {13, 10}, "intel.log", {}, PoseMatchOptions{});  // Auto: stamps -> time
  EXPECT_EQ(m.used, PoseMatching::Timestamp);
  EXPECT_EQ(m.interpolated, 0u);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({1, 1}));
  EXPECT_TRUE(same_bits(m.pose[0].x, 0.1));
  EXPECT_TRUE(same_bits(m.pose[0].y, 1.0 / 3));
  EXPECT_TRUE(same_bits(m.pose[0].theta, -2.0 / 3));
  EXPECT_EQ(m.pose[1].x, 1);
}

// Real logs' stamps go back now and then (intel's four times): the file's
// order is not the search's, and a stamp given twice must mean one pose.
TEST(PoseMatch, TimestampStampsOutOfOrderAndRepeated) {
  TempDir dir;
  const std::string f = dir.file("traj.txt"), g = dir.file("traj2.txt");
  write_file(f, "13 0.5 0 0 0 0 0 1\n10 1 0 0 0 0 0 1\n11 2 0 0 0 0 0 1\n10 1 0 0 0 0 0 1\n");
  const PoseFile file = vasco::read_pose_file(f);
  ASSERT_EQ(file.poses.size(), 4u);
  const PoseMatch m = vasco::match_poses(file, 3, {10, 11, 13}, "intel.log", {}, PoseMatchOptions{});
  EXPECT_EQ(m.pose[0].x, 1);
  EXPECT_EQ(m.pose[1].x, 2);
  EXPECT_EQ(m.pose[2].x, 0.5);
  write_file(g, "10 1 0 0 0 0 0 1\n11 2 0 0 0 0 0 1\n10 1.5 0 0 0 0 0 1\n");
  const std::string e = error_of(
      [&] { vasco::match_poses(vasco::read_pose_file(g), 1, {10}, "intel.log", {}, PoseMatchOptions{}); },
      ErrorCode::BadInput);
  EXPECT_CONTAINS(e, g + ":3: stamp 10 is that of line 1 with another pose");
}

TEST(PoseMatch, TimestampInterpolates) {
  const PoseFile f = three_stamps();
  PoseMatchOptions o = matching(PoseMatching::Timestamp);
  o.tolerance = 1;
  // 10.5: u = 0.5 between (1, 10, 0) and (3, 20, 1): (2, 15, 0.5), all exact.
  // 10.25: u = 0.25: (1.5, 12.5, 0.25). 12: u = 0.5 between 11 and 13.
  const PoseMatch m = vasco::match_poses(f, 3, {10.5, 10.25, 12}, "intel.log", {}, o);
  EXPECT_EQ(m.interpolated, 3u);
  EXPECT_EQ(m.pose[0].x, 2);
  EXPECT_EQ(m.pose[0].y, 15);
  EXPECT_EQ(m.pose[0].theta, 0.5);
  EXPECT_EQ(m.pose[1].x, 1.5);
  EXPECT_EQ(m.pose[1].y, 12.5);
  EXPECT_EQ(m.pose[1].theta, 0.25);
  EXPECT_NEAR(m.pose[2].x, (3 + 0.1) / 2, 1e-15);
  EXPECT_NEAR(m.pose[2].y, (20 + 1.0 / 3) / 2, 1e-14);
  EXPECT_NEAR(m.pose[2].theta, (1 - 2.0 / 3) / 2, 1e-15);
}

TEST(PoseMatch, TimestampShortestArcAcrossPi) {
  // 3.1 -> -3.1 is 0.0832 the short way (through pi), not -6.2 through 0:
  // the midpoint is 3.1 + 0.0416 = pi - 0.0000073, not 0.
  const PoseFile f = stamped_file({{0, {0, 0, 3.1}}, {1, {0, 0, -3.1}}, {2, {0, 0, 3.1}}, {3, {0, 0, 0.5}},
                                   {4, {0, 0, 1.5}}});
  PoseMatchOptions o;
  o.tolerance = 1;
  const PoseMatch m = vasco::match_poses(f, 4, {0.5, 1.5, 2.5, 3.5}, "", {}, o);
  const double short_way = 2 * kPi - 6.2;  // the arc from 3.1 to -3.1 through pi
  EXPECT_NEAR(m.pose[0].theta, 3.1 + short_way / 2, 1e-12);
  EXPECT_NEAR(std::fabs(m.pose[0].theta), kPi, 1e-4);
  EXPECT_NEAR(m.pose[1].theta, -3.1 - short_way / 2, 1e-12);  // -3.1 -> 3.1: the other way through -pi
  EXPECT_NEAR(std::fabs(m.pose[1].theta), kPi, 1e-4);
  // 3.1 -> 0.5 is -2.6 (under pi): taken as it is.
  EXPECT_NEAR(m.pose[2].theta, 1.8, 1e-15);
  EXPECT_EQ(m.pose[3].theta, 1.0);
}

// Keyframes of a SLAM back end, one a second: every scan between two of
// them is interpolated with the defaults, however far it is from both (the
// old rule wanted both within --pose-tolerance, 0.1 s: none of these).
TEST(PoseMatch, TimestampKeyframesASecondApartInterpolateWithTheDefaults) {
  const PoseFile f = stamped_file({{100, {0, 0, 0.5}}, {101, {1, -2, 1.5}}, {102.5, {4, 1, -3}}});
  const std::vector<double> stamps = {100.25, 100.5, 100.75, 101.5, 102.2};
  const PoseMatch m = vasco::match_poses(f, stamps.size(), stamps, "intel.log", {}, PoseMatchOptions{});
  EXPECT_EQ(m.matched, std::vector<uint8_t>(stamps.size(), 1));
  EXPECT_EQ(m.interpolated, stamps.size());
  EXPECT_EQ(m.nearest, 0u);
  // Written out: u = (t - t0) / (t1 - t0); x = x0 + u (x1 - x0), theta by the shorter arc.
  EXPECT_EQ(m.pose[0].x, 0.25);
  EXPECT_EQ(m.pose[0].y, -0.5);
  EXPECT_EQ(m.pose[0].theta, 0.75);
  EXPECT_EQ(m.pose[1].x, 0.5);
  EXPECT_EQ(m.pose[2].y, -1.5);
  // 101.5: u = 1/3 between (1, -2, 1.5) and (4, 1, -3); -3 - 1.5 = -4.5 is
  // 2 pi - 4.5 = 1.783 the short way.
  EXPECT_NEAR(m.pose[3].x, 2, 1e-15);
  EXPECT_NEAR(m.pose[3].y, -1, 1e-15);
  EXPECT_NEAR(m.pose[3].theta, 1.5 + (2 * kPi - 4.5) / 3, 1e-15);
  // 102.2: u = 0.8.
  EXPECT_NEAR(m.pose[4].x, 1 + 0.8 * 3, 1e-14);
  EXPECT_NEAR(m.pose[4].theta, 1.5 + 0.8 * (2 * kPi - 4.5), 1e-14);
}

TEST(PoseMatch, TimestampMaxGapIsInclusive) {
  const PoseFile f = stamped_file({{10, {0, 0, 0}}, {12, {1, 0, 0}}});
  PoseMatchOptions o;
  o.max_gap = 2;  // 10 .. 12 is 2 s, exactly
  PoseMatch m = vasco::match_poses(f, 1, {11.5}, "", {}, o);
  EXPECT_EQ(m.pose[0].x, 0.75);
  EXPECT_EQ(m.interpolated, 1u);
  o.max_gap = 1.5;
  o.skip_unmatched = true;
  m = vasco::match_poses(f, 1, {11.5}, "", {}, o);
  EXPECT_EQ(m.matched[0], 0);
  EXPECT_EQ(m.unmatched, 1u);
  o.max_gap = 0;  // no interpolation: exact stamps (and ends within the tolerance) only
  m = vasco::match_poses(f, 3, {12, 11, 10.0625}, "", {}, o);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({1, 0, 1}));
  EXPECT_EQ(m.nearest, 1u);
  EXPECT_EQ(m.pose[2].x, 0);
  o.max_gap = std::numeric_limits<double>::infinity();  // any gap
  m = vasco::match_poses(f, 1, {11}, "", {}, o);
  EXPECT_EQ(m.pose[0].x, 0.5);
}

// Before the first pose and after the last, a scan takes the end pose,
// unchanged, when it is within the tolerance (inclusive); never extrapolated.
TEST(PoseMatch, TimestampOutsideTheTrajectoryTakesTheEndPoseWithinTheTolerance) {
  const PoseFile f = stamped_file({{10, {0.1, 1.0 / 3, -2.0 / 3}}, {11, {3, 20, 1}}});
  PoseMatchOptions o;
  o.tolerance = 0.25;
  PoseMatch m = vasco::match_poses(f, 4, {9.75, 9.875, 11.125, 11.25}, "", {}, o);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({1, 1, 1, 1}));
  EXPECT_EQ(m.nearest, 4u);
  EXPECT_EQ(m.interpolated, 0u);
  EXPECT_TRUE(same_bits(m.pose[0].x, 0.1));
  EXPECT_TRUE(same_bits(m.pose[0].y, 1.0 / 3));
  EXPECT_TRUE(same_bits(m.pose[1].theta, -2.0 / 3));
  EXPECT_EQ(m.pose[2].y, 20);
  EXPECT_EQ(m.pose[3].theta, 1);
  o.tolerance = 0.125;
  o.skip_unmatched = true;
  m = vasco::match_poses(f, 4, {9.75, 9.875, 11.125, 11.25}, "", {}, o);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({0, 1, 1, 0}));
  EXPECT_EQ(m.unmatched, 2u);
  o.tolerance = 0;  // exact stamps only at the ends
  m = vasco::match_poses(f, 2, {10, 9.999}, "", {}, o);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({1, 0}));
}

// A gap wider than max_gap is a hole in the trajectory: its sides are ends.
TEST(PoseMatch, TimestampInAWideGapTakesTheNearerSideWithinTheTolerance) {
  const PoseFile f = stamped_file({{10, {1, 0, 0}}, {20, {2, 0, 0}}});
  PoseMatchOptions o;
  o.skip_unmatched = true;
  const PoseMatch m = vasco::match_poses(f, 4, {10.0625, 19.9375, 15, 10.25}, "", {}, o);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({1, 1, 0, 0}));
  EXPECT_EQ(m.pose[0].x, 1);
  EXPECT_EQ(m.pose[1].x, 2);
  EXPECT_EQ(m.nearest, 2u);
  EXPECT_EQ(m.interpolated, 0u);
}

TEST(PoseMatch, TimestampNoPoseErrorsStateTheDistances) {
  const PoseFile f = stamped_file({{1083.0, {}}, {1083.9, {}}, {1090.5, {}}});
  const std::vector<long> lines = {810, 811, 812, 813};
  const auto no_pose = [&](double stamp, size_t scan, PoseMatchOptions o = PoseMatchOptions{}) {
    std::vector<double> stamps = {1083.0, 1083.0, 1083.0, 1083.0};
    stamps[scan] = stamp;
    return error_of([&] { vasco::match_poses(f, 4, stamps, "intel.log", lines, o); }, ErrorCode::BadInput);
  };
  std::string what = no_pose(1087, 2);
  EXPECT_CONTAINS(what, "traj.txt: no pose for intel.log line 812 (scan 2, stamp 1087): the poses around it (1083.9 "
                        "and 1090.5) are 6.6 s apart, more than --pose-max-gap 5, and the nearer is 3.1 s away, more "
                        "than --pose-tolerance 0.1");
  what = no_pose(1082.5, 1);
  EXPECT_CONTAINS(what, "traj.txt: no pose for intel.log line 811 (scan 1, stamp 1082.5): 0.5 s before the first pose "
                        "(1083), more than --pose-tolerance 0.1");
  what = no_pose(1090.75, 3);
  EXPECT_CONTAINS(what, "traj.txt: no pose for intel.log line 813 (scan 3, stamp 1090.75): 0.25 s after the last pose "
                        "(1090.5), more than --pose-tolerance 0.1");
  PoseMatchOptions narrow;
  narrow.max_gap = 0.5;
  narrow.tolerance = 0.125;
  what = no_pose(1083.25, 2, narrow);
  EXPECT_CONTAINS(what, "(scan 2, stamp 1083.25): the poses around it (1083 and 1083.9) are 0.9 s apart, more than "
                        "--pose-max-gap 0.5, and the nearer is 0.25 s away, more than --pose-tolerance 0.125");
  what = no_pose(std::numeric_limits<double>::quiet_NaN(), 0);  // a bag message without a stamp
  EXPECT_CONTAINS(what, "traj.txt: no pose for intel.log line 810 (scan 0, stamp nan): the scan has no timestamp");
  // Without a source or lines the scan is named by its index.
  what = error_of([&] { vasco::match_poses(f, 1, {2000}, "", {}, PoseMatchOptions{}); }, ErrorCode::BadInput);
  EXPECT_CONTAINS(what, "traj.txt: no pose for scan 0, stamp 2000: 909.5 s after the last pose");
}

// A distance just over its limit is never printed as the limit.
TEST(PoseMatch, TimestampDistancesJustOverTheLimitShowTheirDigits) {
  const PoseFile f = stamped_file({{10, {}}, {15.0000001, {}}});
  const std::string what = error_of([&] { vasco::match_poses(f, 1, {12}, "", {}, PoseMatchOptions{}); },
                                    ErrorCode::BadInput);
  EXPECT_CONTAINS(what, "are 5.0000001 s apart, more than --pose-max-gap 5,");
}

TEST(PoseMatch, TimestampSkipUnmatchedCounts) {
  const PoseFile f = stamped_file({{10, {1, 0, 0}}, {11, {2, 0, 0}}, {20, {3, 0, 0}}});
  PoseMatchOptions o;
  o.skip_unmatched = true;
  o.tolerance = 0.5;
  // before, exact, interpolated, in the 11..20 gap (wider than 5 s), exact, after.
  const PoseMatch m = vasco::match_poses(f, 6, {9, 10, 10.5, 15, 20, 21}, "intel.log", {}, o);
  EXPECT_EQ(m.matched, std::vector<uint8_t>({0, 1, 1, 0, 1, 0}));
  EXPECT_EQ(m.unmatched, 3u);
  EXPECT_EQ(m.interpolated, 1u);
  EXPECT_EQ(m.pose[2].x, 1.5);
  EXPECT_EQ(m.pose[4].x, 3);
}

TEST(PoseMatch, UsageErrors) {
  const PoseFile g = g2o_file({{0, {}}, {1, {}}});
  std::string what = error_of(
      [&] { vasco::match_poses(g, 2, {1, 2}, "intel.log", {}, matching(PoseMatching::Timestamp)); }, ErrorCode::Usage);
  EXPECT_CONTAINS(what, "graph.g2o: a g2o file has no stamps: match its poses by order or id");
  const PoseFile t = three_stamps();
  what = error_of([&] { vasco::match_poses(t, 3, {10, 11}, "intel.log", {}, PoseMatchOptions{}); }, ErrorCode::Usage);
  EXPECT_CONTAINS(what, "2 stamps for 3 scans");
  for (double bad : {-0.5, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    PoseMatchOptions o;
    o.tolerance = bad;
    what = error_of([&] { vasco::match_poses(t, 1, {10}, "intel.log", {}, o); }, ErrorCode::Usage);
    EXPECT_CONTAINS(what, "tolerance");
  }
  for (double bad : {-0.5, std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity()}) {
    PoseMatchOptions o;
    o.max_gap = bad;
    what = error_of([&] { vasco::match_poses(t, 1, {10}, "intel.log", {}, o); }, ErrorCode::Usage);
    EXPECT_CONTAINS(what, "--pose-max-gap");
  }
  PoseMatchOptions o = matching(PoseMatching::Id);
  o.id_map = {{0, 0}, {0, 1}};
  what = error_of([&] { vasco::match_poses(g, 2, {}, "intel.log", {}, o); }, ErrorCode::Usage);
  EXPECT_CONTAINS(what, "vertex id 0 twice");
}

}  // namespace
