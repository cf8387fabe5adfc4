// log2map with poses from elsewhere (--poses: g2o, CARMEN log, TUM) and with
// several sessions in one grid (--add), run as a program. The expected maps
// are log2map's own on logs this test writes with the poses in them: the
// route a user without these options would take.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "carmen_compat/map_file.h"
#include "map_test_support.h"
#include "tool_support.h"

namespace {

using maptest::TempDir;
using tooltest::contains;
using tooltest::ToolRun;

ToolRun log2map(const std::vector<std::string> &args) { return tooltest::run_tool("log2map", args, true); }

const std::string kIntel = std::string(VASCO_LOGS_DIR) + "/intel.gfs.log.gz";

std::string g17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// A FLASER line split into tokens; the laser pose follows the ranges.
struct Flaser {
  std::vector<std::string> tok;
  size_t pose_at() const { return 2 + std::stoul(tok[1]); }
  double get(int k) const { return std::stod(tok[pose_at() + k]); }
  void set(int k, double v) { tok[pose_at() + k] = g17(v); }
  double stamp() const { return std::stod(tok[pose_at() + 6]); }
  std::string text() const {
    std::string s;
    for (size_t i = 0; i < tok.size(); ++i) s += (i ? " " : "") + tok[i];
    return s + "\n";
  }
};

std::vector<Flaser> intel_scans() {
  std::istringstream in(maptest::gunzip_file(kIntel));
  std::vector<Flaser> out;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("FLASER ", 0) != 0) continue;
    Flaser f;
    std::istringstream ls(line);
    for (std::string t; ls >> t;) f.tok.push_back(t);
    out.push_back(f);
  }
  return out;
}

std::string log_text(const std::vector<Flaser> &scans, size_t begin, size_t end) {
  std::string s;
  for (size_t i = begin; i < end; ++i) s += scans[i].text();
  return s;
}

// What a back end might do after a loop closure: every pose moved a little,
// more towards the end.
std::vector<Flaser> perturbed(std::vector<Flaser> scans) {
  for (size_t i = 0; i < scans.size(); ++i) {
    const double u = double(i) / double(scans.size());
    scans[i].set(0, scans[i].get(0) + 0.05 * u * std::sin(0.1 * double(i)));
    scans[i].set(1, scans[i].get(1) - 0.04 * u);
    scans[i].set(2, scans[i].get(2) + 0.01 * u);
  }
  return scans;
}

std::vector<float> gridmap_of(const std::string &path) {
  const carmen::MapFile mf = carmen::read_map_file(path);
  EXPECT_TRUE(mf.gridmap.has_value()) << path;
  return mf.gridmap ? mf.gridmap->cells : std::vector<float>{};
}

// Cells whose bits differ (a size mismatch counts every cell).
size_t differing(const std::vector<float> &a, const std::vector<float> &b) {
  if (a.size() != b.size()) return std::max(a.size(), b.size());
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(float)) != 0;
  return n;
}

class Log2MapPoses : public ::testing::Test {
 protected:
  void SetUp() override {
    scans_ = intel_scans();
    ASSERT_EQ(scans_.size(), 910u);
    moved_ = perturbed(scans_);
    maptest::write_bytes(dir_.file("moved.log"), log_text(moved_, 0, moved_.size()));
    const ToolRun r = log2map({"--backend", "cpu_double", "--quiet", dir_.file("moved.log"), dir_.file("want.map")});
    ASSERT_EQ(r.status, 0) << r.output;
    want_ = gridmap_of(dir_.file("want.map"));
  }
  TempDir dir_;
  std::vector<Flaser> scans_, moved_;
  std::vector<float> want_;
};

TEST_F(Log2MapPoses, G2oPosesInOrderGiveTheMapOfALogCarryingThem) {
  std::string g2o = "# after a loop closure\n";
  for (size_t i = 0; i < moved_.size(); ++i)
    g2o += "VERTEX_SE2 " + std::to_string(i) + " " + g17(moved_[i].get(0)) + " " + g17(moved_[i].get(1)) + " " +
           g17(moved_[i].get(2)) + "\n";
  g2o += "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n";  // edges are not poses
  maptest::write_bytes(dir_.file("opt.g2o"), g2o);
  for (const char *backend : {"cpu_double", "cpu_threads"}) {
    const ToolRun r = log2map({"--backend", backend, "--poses", dir_.file("opt.g2o"), kIntel, dir_.file("got.map")});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "poses from")) << r.output;
    EXPECT_EQ(differing(gridmap_of(dir_.file("got.map")), want_), 0u) << backend;
  }
}

TEST_F(Log2MapPoses, ACarmenLogsPosesByTimestampGiveTheSameBits) {
  // The stamps are the same numbers in both logs: every scan takes its pose
  // unchanged, none is interpolated.
  const ToolRun r = log2map({"--backend", "cpu_double", "--json", "--poses", dir_.file("moved.log"), kIntel,
                             dir_.file("got.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"posed_from_file\":910")) << r.output;
  EXPECT_EQ(differing(gridmap_of(dir_.file("got.map")), want_), 0u);
}

TEST_F(Log2MapPoses, TumPosesByTimestampAgreeUpToTheQuaternionsRounding) {
  std::string tum = "# t x y z qx qy qz qw\n";
  for (const Flaser &f : moved_) {
    const double th = f.get(2);
    tum += g17(f.stamp()) + " " + g17(f.get(0)) + " " + g17(f.get(1)) + " 0 0 0 " + g17(std::sin(th / 2)) + " " +
           g17(std::cos(th / 2)) + "\n";
  }
  maptest::write_bytes(dir_.file("traj.txt"), tum);
  const ToolRun r = log2map({"--backend", "cpu_double", "--poses", dir_.file("traj.txt"), kIntel, dir_.file("got.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  // The heading goes through sin/cos and atan2: it comes back within a few
  // ulps (|dtheta| < 1e-15 rad). A beam end moves by at most range x dtheta
  // < 50 m x 1e-15 = 5e-14 m, so a cell changes only where a beam end lies
  // that close to a cell border: none of intel's ~160 000 beams is expected
  // to, and a handful is the most we accept (0.01% of the cells).
  const std::vector<float> got = gridmap_of(dir_.file("got.map"));
  ASSERT_EQ(got.size(), want_.size());
  EXPECT_LE(differing(got, want_), want_.size() / 10000);
}

TEST_F(Log2MapPoses, AScanWithoutAPoseIsNamedOrSkippedWhenAsked) {
  // Poses for every other scan only, by timestamp: scan 1 falls between two
  // poses 2 scans apart, more than 0.01 s; with no tolerance, no odd scan
  // takes a neighbour's pose (two are within 0.01 s of one).
  std::string tum;
  for (size_t i = 0; i < moved_.size(); i += 2)
    tum += g17(moved_[i].stamp()) + " " + g17(moved_[i].get(0)) + " " + g17(moved_[i].get(1)) + " 0 0 0 0 1\n";
  maptest::write_bytes(dir_.file("sparse.txt"), tum);
  const ToolRun bad = log2map({"--poses", dir_.file("sparse.txt"), "--pose-max-gap", "0.01", "--pose-tolerance", "0",
                               kIntel, dir_.file("x.map")});
  EXPECT_EQ(bad.status, 1) << bad.output;
  EXPECT_TRUE(contains(bad.output, "sparse.txt")) << bad.output;
  EXPECT_TRUE(contains(bad.output, "scan 1")) << bad.output;
  EXPECT_TRUE(contains(bad.output, "more than --pose-max-gap 0.01")) << bad.output;
  EXPECT_FALSE(maptest::file_exists(dir_.file("x.map")));

  const ToolRun skip = log2map({"--json", "--poses", dir_.file("sparse.txt"), "--pose-max-gap", "0.01",
                                "--pose-tolerance", "0", "--skip-unposed", kIntel, dir_.file("x.map")});
  ASSERT_EQ(skip.status, 0) << skip.output;
  EXPECT_TRUE(contains(skip.output, "\"posed_from_file\":455")) << skip.output;
  EXPECT_TRUE(contains(skip.output, "\"unposed_skipped\":455")) << skip.output;
}

TEST_F(Log2MapPoses, TheTransformAppliesToThePoseFilesPosesToo) {
  // --transform takes the session into the shared frame; the pose file's poses
  // are in the log's own frame, as the log's were (before the fix the file
  // replaced the transformed poses: the map came out untransformed, exit 0).
  std::string g2o;
  for (size_t i = 0; i < moved_.size(); ++i)
    g2o += "VERTEX_SE2 " + std::to_string(i) + " " + g17(moved_[i].get(0)) + " " + g17(moved_[i].get(1)) + " " +
           g17(moved_[i].get(2)) + "\n";
  maptest::write_bytes(dir_.file("opt.g2o"), g2o);
  const ToolRun want = log2map({"--backend", "cpu_double", "-q", "--transform", "1.5,-2,0.5", dir_.file("moved.log"),
                                dir_.file("want_t.map")});
  ASSERT_EQ(want.status, 0) << want.output;
  const ToolRun got = log2map({"--backend", "cpu_double", "-q", "--transform", "1.5,-2,0.5", "--poses",
                               dir_.file("opt.g2o"), kIntel, dir_.file("got_t.map")});
  ASSERT_EQ(got.status, 0) << got.output;
  const carmen::MapFile a = carmen::read_map_file(dir_.file("want_t.map")), b = carmen::read_map_file(dir_.file("got_t.map"));
  ASSERT_TRUE(a.offset && b.offset);
  EXPECT_EQ(a.offset->x, b.offset->x);
  EXPECT_EQ(a.offset->y, b.offset->y);
  EXPECT_EQ(differing(gridmap_of(dir_.file("got_t.map")), gridmap_of(dir_.file("want_t.map"))), 0u);
  EXPECT_NE(differing(gridmap_of(dir_.file("got_t.map")), want_), 0u);  // not the untransformed map
}

TEST_F(Log2MapPoses, SkipUnposedLeavesOutScansOfTheSelectedRunNotBeforeIt) {
  // Poses for scans 100-199 only (g2o vertices 0-99 matched by id); the run is
  // scans 20-219 of the log: its 100 scans with a pose are mapped, the map of
  // a log of scans 100-199 (before the fix the unposed scans went first, and
  // the run became the posed scans 20-99 of what was left: 80 scans).
  std::string g2o, ids;
  for (size_t k = 0; k < 100; ++k) {
    const Flaser &f = moved_[100 + k];
    g2o += "VERTEX_SE2 " + std::to_string(k) + " " + g17(f.get(0)) + " " + g17(f.get(1)) + " " + g17(f.get(2)) + "\n";
    ids += std::to_string(k) + " " + std::to_string(100 + k) + "\n";
  }
  maptest::write_bytes(dir_.file("part.g2o"), g2o);
  maptest::write_bytes(dir_.file("part.ids"), ids);
  maptest::write_bytes(dir_.file("part.log"), log_text(moved_, 100, 200));
  ASSERT_EQ(log2map({"--backend", "cpu_double", "-q", dir_.file("part.log"), dir_.file("want.map")}).status, 0);
  const ToolRun r = log2map({"--backend", "cpu_double", "--json", "--poses", dir_.file("part.g2o"), "--pose-match",
                             "id", "--pose-ids", dir_.file("part.ids"), "--skip-unposed", "--vasco_first_scan", "20",
                             "--vasco_num_scans", "200", kIntel, dir_.file("got.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"posed_from_file\":100")) << r.output;
  EXPECT_TRUE(contains(r.output, "\"unposed_skipped\":100")) << r.output;
  EXPECT_EQ(differing(gridmap_of(dir_.file("got.map")), gridmap_of(dir_.file("want.map"))), 0u);
  // A run with no scan that has a pose says so, naming the file.
  const ToolRun none = log2map({"--poses", dir_.file("part.g2o"), "--pose-match", "id", "--pose-ids",
                                dir_.file("part.ids"), "--skip-unposed", "--vasco_num_scans", "50", kIntel,
                                dir_.file("none.map")});
  EXPECT_EQ(none.status, 1) << none.output;
  EXPECT_TRUE(contains(none.output, "part.g2o")) << none.output;
  EXPECT_TRUE(contains(none.output, "none of the 50 scans")) << none.output;
  EXPECT_TRUE(contains(none.output, "in the selected run")) << none.output;
}

TEST_F(Log2MapPoses, HugePosesAreBlamedOnThePoseFile) {
  // A pose of 1e300 m matched exactly: the grid cannot hold it, and the error
  // names the pose file (it named the log's line).
  std::string tum;
  for (size_t i = 0; i < moved_.size(); ++i)
    tum += g17(moved_[i].stamp()) + " " + (i == 5 ? std::string("1e300") : g17(moved_[i].get(0))) + " " +
           g17(moved_[i].get(1)) + " 0 0 0 0 1\n";
  maptest::write_bytes(dir_.file("huge.txt"), tum);
  const ToolRun huge = log2map({"--poses", dir_.file("huge.txt"), kIntel, dir_.file("x.map")});
  EXPECT_EQ(huge.status, 1) << huge.output;
  EXPECT_TRUE(contains(huge.output, dir_.file("huge.txt") + ": ")) << huge.output;
  EXPECT_FALSE(contains(huge.output, kIntel)) << huge.output;
  // Two poses whose difference overflows: the scan between them has no pose,
  // and the error says why, naming the file and the two lines.
  const double t0 = std::min(moved_[0].stamp(), moved_[1].stamp()) - 0.5;
  const double t1 = std::max(moved_[0].stamp(), moved_[1].stamp()) + 0.5;
  maptest::write_bytes(dir_.file("over.txt"), g17(t0) + " -1e308 0 0 0 0 0 1\n" + g17(t1) + " 1e308 0 0 0 0 0 1\n");
  const ToolRun over = log2map({"--poses", dir_.file("over.txt"), "--vasco_num_scans", "2", "--pose-max-gap", "100",
                                kIntel, dir_.file("x.map")});
  EXPECT_EQ(over.status, 1) << over.output;
  EXPECT_TRUE(contains(over.output, dir_.file("over.txt") + ": no pose for ")) << over.output;
  EXPECT_TRUE(contains(over.output, "the poses of lines 1 and 2 around it interpolate to a pose that is not finite"))
      << over.output;
  EXPECT_FALSE(maptest::file_exists(dir_.file("x.map")));
}

// --max-memory covers the pose file too: a 2.4 MB TUM file of 150,000 poses
// (about 14 MiB as poses) under --max-memory 8 is refused naming the file
// and the line that passed the budget, and nothing is written.
TEST_F(Log2MapPoses, APoseFileBeyondMaxMemoryIsRefusedNamingItsLine) {
  std::string tum;
  tum.reserve(150000 * 16);
  for (int i = 0; i < 150000; ++i) tum += std::to_string(i) + " 0 0 0 0 0 0 1\n";
  maptest::write_bytes(dir_.file("long.txt"), tum);
  const ToolRun r = log2map({"--max-memory", "8", "--poses", dir_.file("long.txt"), kIntel, dir_.file("x.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, dir_.file("long.txt") + ":")) << r.output;
  EXPECT_TRUE(contains(r.output, "(--max-memory)")) << r.output;
  EXPECT_FALSE(maptest::file_exists(dir_.file("x.map")));
}

TEST_F(Log2MapPoses, BadPoseOptionsAreUsageErrors) {
  EXPECT_EQ(log2map({"--pose-tolerance", "0.5", kIntel, dir_.file("x.map")}).status, 2);
  EXPECT_EQ(log2map({"--pose-max-gap", "2", kIntel, dir_.file("x.map")}).status, 2);  // without --poses
  EXPECT_EQ(log2map({"--poses", "p.txt", "--pose-max-gap", "-1", kIntel, dir_.file("x.map")}).status, 2);
  EXPECT_EQ(log2map({"--poses", "p.txt", "--pose-match", "sideways", kIntel, dir_.file("x.map")}).status, 2);
  EXPECT_EQ(log2map({"--transform", "1,2", kIntel, dir_.file("x.map")}).status, 2);
  EXPECT_EQ(log2map({"--add", kIntel + "@1,2,nan", kIntel, dir_.file("x.map")}).status, 2);
  const ToolRun missing = log2map({"--poses", dir_.file("none.g2o"), kIntel, dir_.file("x.map")});
  EXPECT_EQ(missing.status, 1);
  EXPECT_TRUE(contains(missing.output, "none.g2o")) << missing.output;
  std::string short_g2o = "VERTEX_SE2 0 0 0 0\n";
  maptest::write_bytes(dir_.file("short.g2o"), short_g2o);
  const ToolRun count = log2map({"--poses", dir_.file("short.g2o"), kIntel, dir_.file("x.map")});
  EXPECT_EQ(count.status, 1);
  EXPECT_TRUE(contains(count.output, "short.g2o")) << count.output;
  EXPECT_TRUE(contains(count.output, "910")) << count.output;
}

// A robot's poses and the laser's mount on it: laser = compose(robot, mount).
struct Planar {
  double x, y, theta;
};
Planar laser_of(const Planar &robot, const Planar &mount) {
  return {robot.x + std::cos(robot.theta) * mount.x - std::sin(robot.theta) * mount.y,
          robot.y + std::sin(robot.theta) * mount.x + std::cos(robot.theta) * mount.y, robot.theta + mount.theta};
}

// intel's scans as ROBOTLASER1 lines of a robot whose laser sits 0.3 m ahead
// and 0.05 m left, turned by 0.02 rad: the robot at the log's poses, the
// laser where the mount puts it. Laser poses in `lasers`.
std::string robotlaser_log(const std::vector<Flaser> &scans, const Planar &mount, std::vector<Planar> *lasers) {
  std::string text;
  for (const Flaser &f : scans) {
    const size_t n = std::stoul(f.tok[1]);
    const Planar robot{f.get(0), f.get(1), f.get(2)};
    const Planar laser = laser_of(robot, mount);
    lasers->push_back(laser);
    text += "ROBOTLASER1 0 -1.5707963267948966 3.1241393610698497 0.017453292519943295 81.9 0.01 0 " +
            std::to_string(n);
    for (size_t i = 0; i < n; ++i) text += " " + f.tok[2 + i];
    text += " 0 " + g17(laser.x) + " " + g17(laser.y) + " " + g17(laser.theta) + " " + g17(robot.x) + " " +
            g17(robot.y) + " " + g17(robot.theta) + " 0 0 0 0 1000000 " + f.tok[f.pose_at() + 6] + " test " +
            f.tok[f.pose_at() + 6] + "\n";
  }
  return text;
}

TEST_F(Log2MapPoses, RobotPosesTakeTheLaserByTheMount) {
  const Planar mount{0.3, 0.05, 0.02};
  std::vector<Planar> lasers, moved_lasers;
  maptest::write_bytes(dir_.file("robot.log"), robotlaser_log(scans_, mount, &lasers));
  // The optimizer's robot poses (moved_), the laser where the mount puts it.
  std::string g2o;
  std::vector<Flaser> want_scans = moved_;
  for (size_t i = 0; i < moved_.size(); ++i) {
    g2o += "VERTEX_SE2 " + std::to_string(i) + " " + g17(moved_[i].get(0)) + " " + g17(moved_[i].get(1)) + " " +
           g17(moved_[i].get(2)) + "\n";
    const Planar l = laser_of({moved_[i].get(0), moved_[i].get(1), moved_[i].get(2)}, mount);
    want_scans[i].set(0, l.x);
    want_scans[i].set(1, l.y);
    want_scans[i].set(2, l.theta);
  }
  maptest::write_bytes(dir_.file("robot.g2o"), g2o);
  maptest::write_bytes(dir_.file("want_laser.log"), log_text(want_scans, 0, want_scans.size()));
  ToolRun r = log2map({"--backend", "cpu_double", "--quiet", dir_.file("want_laser.log"), dir_.file("want.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<float> want = gridmap_of(dir_.file("want.map"));

  // The mount given: the same arithmetic, the same bits.
  r = log2map({"--backend", "cpu_double", "--poses", dir_.file("robot.g2o"), "--pose-frame", "robot", "--laser-mount",
               "0.3,0.05,0.02", dir_.file("robot.log"), dir_.file("given.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(differing(gridmap_of(dir_.file("given.map")), want), 0u);

  // The mount from each line (inverse(robot) o laser): the mount comes back
  // within a few ulps (|d| < 1e-15 m and rad), a beam end moves by less than
  // 50 m x 1e-15: as with the TUM quaternions, at most a handful of cells.
  r = log2map({"--backend", "cpu_double", "--poses", dir_.file("robot.g2o"), "--pose-frame", "robot",
               dir_.file("robot.log"), dir_.file("lines.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<float> lines = gridmap_of(dir_.file("lines.map"));
  ASSERT_EQ(lines.size(), want.size());
  EXPECT_LE(differing(lines, want), want.size() / 10000);

  // FLASER lines carry no mount: say so, and how to give one.
  r = log2map({"--poses", dir_.file("robot.g2o"), "--pose-frame", "robot", kIntel, dir_.file("x.map")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--laser-mount")) << r.output;
}

// Several sessions: two halves of intel as two logs give the map of the
// whole log; the second half in another frame, with its transform, gives the
// map of one log holding those scans taken into the shared frame.
TEST_F(Log2MapPoses, TwoSessionsGiveTheMapOfOneLogHoldingBoth) {
  maptest::write_bytes(dir_.file("a.log"), log_text(scans_, 0, 400));
  maptest::write_bytes(dir_.file("b.log"), log_text(scans_, 400, scans_.size()));
  for (const char *backend : {"cpu_double", "cpu_threads"}) {
    ToolRun r = log2map({"--backend", backend, dir_.file("a.log"), "--add", dir_.file("b.log"), dir_.file("ab.map")});
    ASSERT_EQ(r.status, 0) << r.output;
    r = log2map({"--backend", backend, kIntel, dir_.file("whole.map")});
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(differing(gridmap_of(dir_.file("ab.map")), gridmap_of(dir_.file("whole.map"))), 0u) << backend;
  }
}

TEST_F(Log2MapPoses, ASessionsTransformTakesItIntoTheSharedFrame) {
  // b's poses as its own robot saw them: in a frame 3 m east, 1 m south and
  // turned by 0.25 rad. The shared-frame log holds x' = tx + cos(a) x -
  // sin(a) y, y' = ty + sin(a) x + cos(a) y, theta' = theta + a.
  const double tx = 3.0, ty = -1.0, a = 0.25;
  std::vector<Flaser> shared = scans_;
  for (size_t i = 400; i < shared.size(); ++i) {
    const double x = scans_[i].get(0), y = scans_[i].get(1), th = scans_[i].get(2);
    shared[i].set(0, tx + std::cos(a) * x - std::sin(a) * y);
    shared[i].set(1, ty + std::sin(a) * x + std::cos(a) * y);
    shared[i].set(2, th + a);
  }
  maptest::write_bytes(dir_.file("a.log"), log_text(scans_, 0, 400));
  maptest::write_bytes(dir_.file("b.log"), log_text(scans_, 400, scans_.size()));
  maptest::write_bytes(dir_.file("shared.log"), log_text(shared, 0, shared.size()));
  ToolRun r = log2map({"--backend", "cpu_double", "--json", dir_.file("a.log"), "--add",
                       dir_.file("b.log") + "@3,-1,0.25", dir_.file("ab.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"sessions\":2")) << r.output;
  r = log2map({"--backend", "cpu_double", dir_.file("shared.log"), dir_.file("shared.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(differing(gridmap_of(dir_.file("ab.map")), gridmap_of(dir_.file("shared.map"))), 0u);
}

// ---------------------------------------------------------------------------
// Keyframes of a SLAM back end: a pose every 5th scan of fr101 (its scans are
// 0.2 to 0.85 s apart, so the keyframes about a second), in a TUM file.

const std::string kFr101 = std::string(VASCO_LOGS_DIR) + "/fr101.carmen.log.gz";
constexpr size_t kKeyframeScans = 400;  // the first 400 scans: enough, and quick
constexpr double kTwoPi = 6.283185307179586;

// A log's lines up to its n-th FLASER line; FLASER lines split, the others
// (PARAM, ODOM, RLASER, comments) kept as they are.
struct LogLines {
  std::vector<std::string> other;  // other[i]: the lines before scans[i] (and after the last, at the end)
  std::vector<Flaser> scans;
  std::string text() const {
    std::string s;
    for (size_t i = 0; i < scans.size(); ++i) s += other[i] + scans[i].text();
    return s + other.back();
  }
};

LogLines first_scans(const std::string &path, size_t n) {
  std::istringstream in(maptest::gunzip_file(path));
  LogLines log;
  log.other.emplace_back();
  for (std::string line; std::getline(in, line) && log.scans.size() < n;) {
    if (line.rfind("FLASER ", 0) != 0) {
      log.other.back() += line + "\n";
      continue;
    }
    Flaser f;
    std::istringstream ls(line);
    for (std::string t; ls >> t;) f.tok.push_back(t);
    log.scans.push_back(f);
    log.other.emplace_back();
  }
  return log;
}

// The keyframes: every 5th scan and the last, their poses moved as an
// optimizer might (headings wrapped into [-pi, pi], as a TUM yaw reads back).
struct Keyframe {
  size_t scan;
  double stamp, x, y, theta;
};

std::vector<Keyframe> keyframes_of(const std::vector<Flaser> &scans) {
  std::vector<Keyframe> k;
  for (size_t i = 0; i < scans.size(); ++i) {
    if (i % 5 != 0 && i + 1 != scans.size()) continue;
    const double a = double(i);
    k.push_back({i, scans[i].stamp(), scans[i].get(0) + 0.05 * std::sin(a), scans[i].get(1) - 0.03 * std::cos(a),
                 std::remainder(scans[i].get(2) + 0.01 * std::sin(0.5 * a), kTwoPi)});
  }
  return k;
}

std::string tum_of(const std::vector<Keyframe> &keys) {
  std::string tum = "# t x y z qx qy qz qw\n";
  for (const Keyframe &k : keys)
    tum += g17(k.stamp) + " " + g17(k.x) + " " + g17(k.y) + " 0 0 0 " + g17(std::sin(k.theta / 2)) + " " +
           g17(std::cos(k.theta / 2)) + "\n";
  return tum;
}

// What a scan between keyframes a and b should get, written out here:
// u = (t - ta) / (tb - ta); x, y linear; theta by the shorter arc.
void set_between(Flaser &f, const Keyframe &a, const Keyframe &b) {
  const double u = (f.stamp() - a.stamp) / (b.stamp - a.stamp);
  double d = std::remainder(b.theta - a.theta, kTwoPi);
  if (d >= kTwoPi / 2) d -= kTwoPi;
  f.set(0, a.x + u * (b.x - a.x));
  f.set(1, a.y + u * (b.y - a.y));
  f.set(2, a.theta + u * d);
}

class Log2MapKeyframes : public ::testing::Test {
 protected:
  void SetUp() override {
    log_ = first_scans(kFr101, kKeyframeScans);
    ASSERT_EQ(log_.scans.size(), kKeyframeScans);
    keys_ = keyframes_of(log_.scans);
    maptest::write_bytes(dir_.file("fr101.log"), log_.text());
    maptest::write_bytes(dir_.file("keyframes.txt"), tum_of(keys_));
  }
  TempDir dir_;
  LogLines log_;
  std::vector<Keyframe> keys_;
};

TEST_F(Log2MapKeyframes, AKeyframeASecondMapsWithTheDefaults) {
  // The map of a log carrying the poses interpolated here.
  LogLines want = log_;
  size_t k = 0;
  for (size_t i = 0; i < want.scans.size(); ++i) {
    while (keys_[k + 1].scan < i) ++k;
    if (keys_[k].scan == i || keys_[k + 1].scan == i) {
      const Keyframe &key = keys_[k].scan == i ? keys_[k] : keys_[k + 1];
      want.scans[i].set(0, key.x);
      want.scans[i].set(1, key.y);
      want.scans[i].set(2, key.theta);
    } else {
      set_between(want.scans[i], keys_[k], keys_[k + 1]);
    }
  }
  maptest::write_bytes(dir_.file("want.log"), want.text());
  ToolRun r = log2map({"--backend", "cpu_threads", "--quiet", dir_.file("want.log"), dir_.file("want.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  r = log2map({"--backend", "cpu_threads", "--json", "--poses", dir_.file("keyframes.txt"), dir_.file("fr101.log"),
               dir_.file("got.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"posed_from_file\":" + std::to_string(kKeyframeScans))) << r.output;
  // The keyframes' headings come back from the quaternions within a few
  // ulps, and so do the interpolated ones: as with intel's TUM file above,
  // at most 0.01% of the cells may differ.
  const std::vector<float> want_map = gridmap_of(dir_.file("want.map"));
  const std::vector<float> got = gridmap_of(dir_.file("got.map"));
  ASSERT_EQ(got.size(), want_map.size());
  EXPECT_LE(differing(got, want_map), want_map.size() / 10000);
  // Not the map of the log's own poses: the file's were used.
  r = log2map({"--backend", "cpu_threads", "--quiet", dir_.file("fr101.log"), dir_.file("own.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_GT(differing(gridmap_of(dir_.file("own.map")), want_map), want_map.size() / 10000);
}

// "%.6g": how the messages write a distance that is not close to its limit.
std::string g6(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

TEST_F(Log2MapKeyframes, AGapOverTheLimitNamesTheDistances) {
  const ToolRun r = log2map({"--poses", dir_.file("keyframes.txt"), "--pose-max-gap", "0.5", dir_.file("fr101.log"),
                             dir_.file("x.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  // Scan 1 lies between the keyframes of scans 0 and 5, about a second apart.
  const double t = log_.scans[1].stamp(), gap = keys_[1].stamp - keys_[0].stamp;
  const double nearer = std::min(t - keys_[0].stamp, keys_[1].stamp - t);
  ASSERT_GT(gap, 0.5);
  ASSERT_GT(nearer, 0.1);
  EXPECT_TRUE(contains(r.output, "keyframes.txt: no pose for")) << r.output;
  EXPECT_TRUE(contains(r.output, "(scan 1, stamp ")) << r.output;
  EXPECT_TRUE(contains(r.output, "are " + g6(gap) + " s apart, more than --pose-max-gap 0.5, and the nearer is " +
                                     g6(nearer) + " s away, more than --pose-tolerance 0.1"))
      << r.output;
  EXPECT_FALSE(maptest::file_exists(dir_.file("x.map")));
  const ToolRun any = log2map({"--backend", "cpu_threads", "--quiet", "--poses", dir_.file("keyframes.txt"),
                               "--pose-max-gap", "inf", dir_.file("fr101.log"), dir_.file("x.map")});
  EXPECT_EQ(any.status, 0) << any.output;
}

TEST_F(Log2MapKeyframes, ScansAfterTheLastPoseTakeItWithinTheTolerance) {
  // The trajectory ends at scan 300's keyframe; scans 301 to 399 come after.
  std::vector<Keyframe> cut(keys_.begin(), keys_.begin() + 61);
  ASSERT_EQ(cut.back().scan, 300u);
  maptest::write_bytes(dir_.file("cut.txt"), tum_of(cut));
  const double after = log_.scans[301].stamp() - cut.back().stamp;  // 0.2 s or so: more than 0.1
  ToolRun r = log2map({"--poses", dir_.file("cut.txt"), dir_.file("fr101.log"), dir_.file("x.map")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "(scan 301, stamp ")) << r.output;
  ASSERT_GT(after, 0.1);
  EXPECT_TRUE(contains(r.output, g6(after) + " s after the last pose (")) << r.output;
  EXPECT_TRUE(contains(r.output, "), more than --pose-tolerance 0.1")) << r.output;
  // Within the tolerance: every later scan takes the last pose, unchanged.
  const double span = log_.scans.back().stamp() - cut.back().stamp;
  r = log2map({"--backend", "cpu_threads", "--json", "--poses", dir_.file("cut.txt"), "--pose-tolerance",
               g17(span), dir_.file("fr101.log"), dir_.file("within.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"posed_from_file\":" + std::to_string(kKeyframeScans))) << r.output;
  // Just short of it, the last scan has none.
  r = log2map({"--json", "--poses", dir_.file("cut.txt"), "--pose-tolerance", g17(span * (1 - 1e-9)),
               "--skip-unposed", dir_.file("fr101.log"), dir_.file("short.map")});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "\"unposed_skipped\":1")) << r.output;
}

}  // namespace
