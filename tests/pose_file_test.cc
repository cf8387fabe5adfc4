// Tests of reading the pose files of SLAM back ends and "id scan" maps
// (vasco_gpu/pipeline/pose_file.h). Expected values are worked out by hand
// here, not taken from the code under test.
#include "vasco_gpu/pipeline/pose_file.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <clocale>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "carmen_compat/error.h"
#include "pose_test_support.h"
#include "temp_dir.h"
#include "vasco_gpu/internal/se2.h"

namespace {

using carmen::ErrorCode;
using pose_test::error_of;
using pose_test::g17;
using pose_test::same_bits;
using pose_test::write_file;
using vasco::PoseFile;
using vasco::PoseFileFormat;
using vasco::StampedPose;

// The error of reading `text` as a pose file named `name` (in its own
// directory, so the message's path is known).
struct ReadError {
  std::string path, what;
};
ReadError read_error(const std::string &name, const std::string &text,
                     PoseFileFormat format = PoseFileFormat::Auto) {
  TempDir dir;
  ReadError r;
  r.path = dir.file(name);
  write_file(r.path, text);
  r.what = error_of([&] { vasco::read_pose_file(r.path, format); }, ErrorCode::BadInput);
  return r;
}

// ---------------------------------------------------------------------------
// Reading.

TEST(PoseFileRead, TumLinesCommentsAndBlankLines) {
  TempDir dir;
  const std::string path = dir.file("traj.txt");
  write_file(path,
             "# timestamp tx ty tz qx qy qz qw\n"
             "\n"
             "1.5 10 20 0.5 0 0 0 1\n"
             "   # an indented comment\n"
             "2.25\t-1 -2 0 0 0 1 0\r\n"  // tabs and CRLF; yaw pi
             "+3 +4 5 6 0 0 0 -1\n");      // a '+' sign as strtod takes it; q = -identity is yaw 0
  const PoseFile f = vasco::read_pose_file(path);
  EXPECT_EQ(f.format, PoseFileFormat::Tum);
  EXPECT_TRUE(f.has_stamps());
  ASSERT_EQ(f.poses.size(), 3u);
  EXPECT_EQ(f.poses[0].stamp, 1.5);
  EXPECT_EQ(f.poses[0].pose.x, 10);
  EXPECT_EQ(f.poses[0].pose.y, 20);
  EXPECT_EQ(f.poses[0].pose.theta, 0);
  EXPECT_EQ(f.poses[0].line, 3);
  EXPECT_EQ(f.poses[0].id, -1);
  EXPECT_EQ(f.poses[1].stamp, 2.25);
  EXPECT_EQ(f.poses[1].line, 5);
  // (0,0,1,0): atan2(2(0*1 + 0), 1 - 2*1) = atan2(+0, -1) = pi exactly as a double.
  EXPECT_EQ(f.poses[1].pose.theta, std::atan2(0.0, -1.0));
  EXPECT_EQ(f.poses[2].stamp, 3);
  EXPECT_EQ(f.poses[2].pose.x, 4);
  // (0,0,0,-1): atan2(2(-1*0 + 0), 1) = atan2(-0, 1) = -0.
  EXPECT_EQ(f.poses[2].pose.theta, 0);
}

// A quaternion made from a known yaw gives it back within 1e-15.
//
// Why 1e-15 holds, for q = (0, 0, s, c), s = sin(psi/2), c = cos(psi/2):
// u = 2^-53; sin, cos, hypot and atan2 are taken to be within 1 ulp (glibc's
// documented bound on x86-64), i.e. a relative error of at most 2u; no FMA
// (-ffp-contract=off). qx = qy = 0 makes the qx*qy and qy^2 terms exactly 0.
// To first order the yaw error is the sum of
//  - the quaternion itself: s, c each off by 2u relative move psi/2 by at
//    most 2u|s c|*2, so psi by 4u|sin psi|;
//  - normalising: a common factor (1 + a), |a| <= 2u (hypot), which
//    atan2(2wz, 1 - 2z^2) sees as 2|a||sin psi|, plus one rounding in each
//    division (|sin psi|(2 - cos psi) and |sin psi cos psi|, times u);
//  - 2wz (one rounding: u|sin psi cos psi|), z^2 (u|sin psi|(1 - cos psi)),
//    1 - 2z^2 (u|sin psi cos psi|), where x^2 + y^2 = 1 into atan2;
//  - atan2's own 1 ulp of psi.
// psi = 0.5: 1.92u + 1.92u + 0.54u + 0.42u + 0.42u + 0.06u + 0.42u + 1u (ulp 0.5 = u)
//   = 6.7u = 7.4e-16;  psi = 3.0: 0.56u + 0.56u + 0.42u + 0.14u + 0.14u + 0.28u
//   + 0.14u + 4u (ulp 3 = 4u) = 6.3u = 7.0e-16;  psi = 0.25 and 0 are
// smaller. Both are below 1e-15 (9.0u). (psi near 2 could reach 1.1e-15 in
// this worst case; those are not asserted here.) The file's %.17g text reads
// back bit for bit, so it adds nothing; scaling q by 2 is exact and leaves the
// normalised q unchanged.
TEST(PoseFileRead, TumYawFromQuaternionWithin1e15) {
  const double yaws[] = {0.0, 0.25, -0.25, 0.5, -0.5, 3.0, -3.0};
  TempDir dir;
  const std::string path = dir.file("yaw.tum");
  std::string text;
  double t = 0;
  for (double scale : {1.0, 2.0})
    for (double psi : yaws)
      text += g17(t += 1) + " 0 0 0 0 0 " + g17(scale * std::sin(psi / 2)) + " " + g17(scale * std::cos(psi / 2)) +
              "\n";
  write_file(path, text);
  const PoseFile f = vasco::read_pose_file(path);
  ASSERT_EQ(f.poses.size(), 14u);
  for (size_t i = 0; i < f.poses.size(); ++i) EXPECT_NEAR(f.poses[i].pose.theta, yaws[i % 7], 1e-15) << i;
  for (double psi : yaws) EXPECT_NEAR(vasco::yaw_of_quaternion(0, 0, std::sin(psi / 2), std::cos(psi / 2)), psi, 1e-15);
}

// Doubles printed with %.17g read back bit for bit in every format.
TEST(PoseFileRead, ValuesRoundTripBitForBit) {
  std::mt19937_64 rng(20240601);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<double> v = {0.1, 1.0 / 3, -2.0 / 3, 1e-300, -1e300, 123456.789012345678, 5e-324,
                           std::numeric_limits<double>::max(), std::numeric_limits<double>::min()};
  for (int i = 0; i < 60; ++i) v.push_back(unit(rng) * std::pow(10.0, static_cast<int>(rng() % 21) - 10));
  TempDir dir;
  const std::string tum = dir.file("r.txt"), g2o = dir.file("r.g2o"), log = dir.file("r.log");
  std::string tum_text, g2o_text, log_text;
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string a = g17(v[i]), b = g17(v[(i + 1) % v.size()]), c = g17(v[(i + 2) % v.size()]);
    tum_text += g17(1000 + 0.001 * double(i)) + " " + a + " " + b + " 0 0 0 0 1\n";
    g2o_text += "VERTEX_SE2 " + std::to_string(i) + " " + a + " " + b + " " + c + "\n";
    log_text += "FLASER 1 1.0 " + a + " " + b + " " + c + " 0 0 0 " + g17(1000 + 0.001 * double(i)) + " h 0\n";
  }
  write_file(tum, tum_text);
  write_file(g2o, g2o_text);
  write_file(log, log_text);
  const PoseFile ft = vasco::read_pose_file(tum), fg = vasco::read_pose_file(g2o), fl = vasco::read_pose_file(log);
  ASSERT_EQ(ft.poses.size(), v.size());
  ASSERT_EQ(fg.poses.size(), v.size());
  ASSERT_EQ(fl.poses.size(), v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    const double a = v[i], b = v[(i + 1) % v.size()], c = v[(i + 2) % v.size()];
    const double stamp = 1000 + 0.001 * double(i);
    EXPECT_TRUE(same_bits(ft.poses[i].stamp, stamp) && same_bits(fl.poses[i].stamp, stamp)) << i;
    EXPECT_TRUE(same_bits(ft.poses[i].pose.x, a) && same_bits(ft.poses[i].pose.y, b)) << i;
    EXPECT_TRUE(same_bits(fg.poses[i].pose.x, a) && same_bits(fg.poses[i].pose.y, b) &&
                same_bits(fg.poses[i].pose.theta, c))
        << i;
    EXPECT_TRUE(same_bits(fl.poses[i].pose.x, a) && same_bits(fl.poses[i].pose.y, b) &&
                same_bits(fl.poses[i].pose.theta, c))
        << i;
  }
}

TEST(PoseFileRead, G2oVerticesOnly) {
  TempDir dir;
  const std::string path = dir.file("graph.G2O");  // the extension in any case
  write_file(path,
             "# made by hand\n"
             "VERTEX_SE2 0 0 0 0\n"
             "VERTEX_XY 100 5 5\n"
             "VERTEX_SE2 7 1.5 -2.5 0.25\n"
             "EDGE_SE2 0 7 1.5 -2.5 0.25 1 0 0 1 0 1\n"
             "FIX 0\n"
             "VERTEX_SE2 3 4 5 -3\n");
  const PoseFile f = vasco::read_pose_file(path);
  EXPECT_EQ(f.format, PoseFileFormat::G2o);
  EXPECT_FALSE(f.has_stamps());
  ASSERT_EQ(f.poses.size(), 3u);
  EXPECT_EQ(f.poses[0].id, 0);
  EXPECT_EQ(f.poses[1].id, 7);
  EXPECT_EQ(f.poses[1].line, 4);
  EXPECT_EQ(f.poses[1].pose.x, 1.5);
  EXPECT_EQ(f.poses[1].pose.y, -2.5);
  EXPECT_EQ(f.poses[1].pose.theta, 0.25);
  EXPECT_EQ(f.poses[2].id, 3);  // file order, not id order
  EXPECT_EQ(f.poses[2].line, 7);
  EXPECT_EQ(f.poses[2].pose.theta, -3);
  for (const StampedPose &p : f.poses) EXPECT_TRUE(std::isnan(p.stamp));
}

// Two FLASER lines and one ROBOTLASER1 line; ODOM, PARAM and RLASER (the rear
// laser) give no poses.
const char kCarmenLog[] =
    "# CARMEN Logfile\n"
    "PARAM robot_frontlaser_offset 0.25 0 host 0\n"
    "ODOM 1 2 0.5 0 0 0 99.5 host 1\n"
    "FLASER 3 1.0 2.0 3.0 10.5 20.25 0.5 10 20 0.5 100.5 host 1\n"
    "RLASER 3 1.0 2.0 3.0 -1 -1 -1 10 20 0.5 100.6 host 1\n"
    "FLASER 3 1.0 2.0 3.0 11.5 21.25 -0.5 11 21 -0.5 101.5 host 2\n"
    "ROBOTLASER1 0 -1.5707963 3.1415927 1.5707963 81.9 0.01 0 3 1.0 2.0 3.0 0 "
    "12.5 22.25 1.5 12 22 1.5 0.3 0.0 0.3 0.1 1000000 102.5 host 3\n";

void expect_carmen_poses(const PoseFile &f) {
  EXPECT_EQ(f.format, PoseFileFormat::CarmenLog);
  EXPECT_TRUE(f.has_stamps());
  ASSERT_EQ(f.poses.size(), 3u);
  const double stamps[] = {100.5, 101.5, 102.5}, xs[] = {10.5, 11.5, 12.5}, ys[] = {20.25, 21.25, 22.25},
               thetas[] = {0.5, -0.5, 1.5};
  const long lines[] = {4, 6, 7};
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(f.poses[i].stamp, stamps[i]);
    EXPECT_EQ(f.poses[i].pose.x, xs[i]);  // the laser pose, not the odometry
    EXPECT_EQ(f.poses[i].pose.y, ys[i]);
    EXPECT_EQ(f.poses[i].pose.theta, thetas[i]);
    EXPECT_EQ(f.poses[i].line, lines[i]);
    EXPECT_EQ(f.poses[i].id, -1);
  }
}

TEST(PoseFileRead, CarmenLogFlaserAndRobotlaser1) {
  TempDir dir;
  const std::string log = dir.file("poses.log"), clf = dir.file("poses.CLF"), txt = dir.file("poses.txt");
  for (const std::string &p : {log, clf, txt}) write_file(p, kCarmenLog);
  expect_carmen_poses(vasco::read_pose_file(log));
  expect_carmen_poses(vasco::read_pose_file(clf));
  expect_carmen_poses(vasco::read_pose_file(txt, PoseFileFormat::CarmenLog));  // named: the extension does not matter
}

TEST(PoseFileRead, CarmenLogGzipped) {
  TempDir dir;
  const std::string path = dir.file("poses.log.gz");
  gzFile gz = gzopen(path.c_str(), "wb");
  ASSERT_NE(gz, nullptr);
  gzwrite(gz, kCarmenLog, static_cast<unsigned>(std::strlen(kCarmenLog)));
  gzclose(gz);
  expect_carmen_poses(vasco::read_pose_file(path));
}

TEST(PoseFileRead, CarmenLogErrors) {
  ReadError e = read_error("none.log", "ODOM 1 2 0.5 0 0 0 99.5 host 1\n");
  EXPECT_CONTAINS(e.what, e.path + ": no poses");
  EXPECT_CONTAINS(e.what, "FLASER");
  // Stamps that go back are read (real logs have them); matching sorts them.
  TempDir dir;
  write_file(dir.file("back.log"),
             "FLASER 1 1.0 1 2 3 1 2 3 100.5 host 1\n"
             "ODOM 1 2 0.5 0 0 0 99.5 host 1\n"
             "FLASER 1 1.0 4 5 6 1 2 3 100.25 host 1\n");
  const PoseFile back = vasco::read_pose_file(dir.file("back.log"));
  ASSERT_EQ(back.poses.size(), 2u);
  EXPECT_EQ(back.poses[1].stamp, 100.25);
  EXPECT_EQ(back.poses[1].line, 3);
  e = read_error("bad.log", "FLASER 1 1.0 1 abc 3 1 2 3 100.5 host 1\n");  // the log reader's own message
  EXPECT_CONTAINS(e.what, e.path + ":1:");
}

TEST(PoseFileRead, TumErrorsNameFileAndLine) {
  const std::string ok = "1 0 0 0 0 0 0 1\n";
  ReadError e = read_error("traj.txt", ok + "2 0 abc 0 0 0 0 1\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: field 3 ('abc') is not a number");
  e = read_error("traj.txt", ok + "2 0 0 0 0 0 1\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: 7 fields, expected 8");
  e = read_error("traj.txt", ok + "2 0 0 0 0 0 0 1 9\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: 9 fields, expected 8");
  e = read_error("traj.txt", ok + "2 0 0 nan 0 0 0 1\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: field 4 ('nan') is not finite");
  e = read_error("traj.txt", ok + "2 inf 0 0 0 0 0 1\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: field 2 ('inf') is not finite");
  e = read_error("traj.txt", ok + "2 1e999 0 0 0 0 0 1\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: field 2 ('1e999')");
  e = read_error("traj.txt", ok + "2 1,5 0 0 0 0 0 1\n");  // a decimal comma is no number here
  EXPECT_CONTAINS(e.what, e.path + ":2: field 2 ('1,5') is not a number");
  e = read_error("traj.txt", ok + "2 0 0 0 0 0 0 0\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: the quaternion");
  EXPECT_CONTAINS(e.what, "norm 0");
  e = read_error("traj.txt", ok + "2 0 0 0 1e308 1e308 1e308 1e308\n");  // norm 2e308 overflows
  EXPECT_CONTAINS(e.what, e.path + ":2: the quaternion");
  e = read_error("traj.txt", "# nothing\n\n");
  EXPECT_CONTAINS(e.what, e.path + ": no poses: expected TUM lines 't x y z qx qy qz qw'");
  e = read_error("traj.txt", "");
  EXPECT_CONTAINS(e.what, e.path + ": no poses");
  e = read_error("traj.txt", ok + std::string("2 0 0 0 0 0 0 1\0\n", 17));
  EXPECT_CONTAINS(e.what, e.path + ":2: NUL byte");
  e = read_error("traj.txt.gz", std::string("\x1f\x8b\x08\0\0\0\0\0", 8));
  EXPECT_CONTAINS(e.what, e.path + ":1: gzip data");
}

TEST(PoseFileRead, OverLongLineRefused) {
  // 64 KiB of digits is refused without being stored; 60 KiB is only a bad field.
  ReadError e = read_error("long.txt", "1 0 0 0 0 0 0 1\n2 " + std::string(70000, '7') + "\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: line longer than 65536 bytes");
  e = read_error("long.txt", "1 0 0 0 0 0 0 1 " + std::string(60000, 'x') + "\n");
  EXPECT_CONTAINS(e.what, e.path + ":1: 9 fields");
}

TEST(PoseFileRead, G2oErrorsNameFileAndLine) {
  const std::string ok = "VERTEX_SE2 0 0 0 0\n";
  ReadError e = read_error("graph.g2o", ok + "EDGE_SE2 0 1 1 0 0\nVERTEX_SE2 1.5 0 0 0\n");
  EXPECT_CONTAINS(e.what, e.path + ":3: field 1 ('1.5') is not an integer");
  e = read_error("graph.g2o", ok + "VERTEX_SE2 -4 0 0 0\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: field 1 ('-4') is negative");
  e = read_error("graph.g2o", ok + "VERTEX_SE2 1 0 0\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: VERTEX_SE2 with 3 fields, expected 4");
  e = read_error("graph.g2o", ok + "VERTEX_SE2 1 0 zz 0\n");
  EXPECT_CONTAINS(e.what, e.path + ":2: field 3 ('zz') is not a number");
  e = read_error("graph.g2o", ok + "VERTEX_SE2 1 0 0 0\nFIX 0\nVERTEX_SE2 0 1 1 1\n");
  EXPECT_CONTAINS(e.what, e.path + ":4: vertex id 0 repeated (first at line 1)");
  e = read_error("graph.g2o", "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nVERTEX_XY 3 1 1\n");
  EXPECT_CONTAINS(e.what, e.path + ": no poses: no VERTEX_SE2 lines");
}

// Pose files count against the run's memory budget while they are read: the
// pose that passes it is refused at its line, before the rest is read.
// Each pose is charged 2 x sizeof(StampedPose) (pose_file.cc says why), so a
// budget of 100 poses' worth takes 100 and refuses line 101 (or 101 + the
// comment line).
TEST(PoseFileRead, APoseFileBeyondTheMemoryBudgetIsRefusedAtTheLineThatPassesIt) {
  TempDir dir;
  std::string tum = "# t x y z qx qy qz qw\n", g2o, log;
  for (int i = 0; i < 1000; ++i) {
    tum += std::to_string(i) + " 0 0 0 0 0 0 1\n";
    g2o += "VERTEX_SE2 " + std::to_string(i) + " 0 0 0\n";
    log += "FLASER 1 1.0 0 0 0 0 0 0 " + std::to_string(i) + " h 0\n";
  }
  write_file(dir.file("t.txt"), tum);
  write_file(dir.file("v.g2o"), g2o);
  write_file(dir.file("l.log"), log);
  vasco::PoseReadLimits limits;
  limits.budget_option = "--max-memory";
  limits.memory_budget = 100 * 2 * sizeof(vasco::StampedPose);
  std::string what = error_of([&] { vasco::read_pose_file(dir.file("t.txt"), PoseFileFormat::Auto, limits); },
                              ErrorCode::OutOfMemory);
  EXPECT_CONTAINS(what, dir.file("t.txt") + ":102: ");
  EXPECT_CONTAINS(what, "(--max-memory)");
  what = error_of([&] { vasco::read_pose_file(dir.file("l.log"), PoseFileFormat::Auto, limits); },
                  ErrorCode::OutOfMemory);
  EXPECT_CONTAINS(what, dir.file("l.log") + ":101: ");
  what = error_of([&] { vasco::read_pose_file(dir.file("v.g2o"), PoseFileFormat::Auto, limits); },
                  ErrorCode::OutOfMemory);
  EXPECT_CONTAINS(what, dir.file("v.g2o") + ":");  // before line 101: the id index is charged too
  limits.memory_budget = 1000 * 2 * sizeof(vasco::StampedPose);
  EXPECT_EQ(vasco::read_pose_file(dir.file("t.txt"), PoseFileFormat::Auto, limits).poses.size(), 1000u);
  EXPECT_EQ(vasco::read_pose_file(dir.file("v.g2o")).poses.size(), 1000u);  // no budget: no limit
}

TEST(PoseFileRead, UnreadableFileIsAnIoError) {
  TempDir dir;
  const std::string missing = dir.file("missing.txt");
  std::string what = error_of([&] { vasco::read_pose_file(missing); }, ErrorCode::Io);
  EXPECT_CONTAINS(what, missing + ": cannot open");
  what = error_of([&] { vasco::read_pose_file(dir.file("missing.g2o")); }, ErrorCode::Io);
  EXPECT_CONTAINS(what, "missing.g2o");
  what = error_of([&] { vasco::read_pose_file(dir.file("missing.log")); }, ErrorCode::Io);
  EXPECT_CONTAINS(what, "missing.log");
  what = error_of([&] { vasco::read_pose_id_map(dir.file("missing.map")); }, ErrorCode::Io);
  EXPECT_CONTAINS(what, "missing.map");
}

// Under a decimal-comma locale the numbers are still read in the C locale.
TEST(PoseFileRead, IgnoresTheProcessLocale) {
  const std::string saved = std::setlocale(LC_NUMERIC, nullptr);
  const char *found = nullptr;
  for (const char *name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8"})
    if ((found = std::setlocale(LC_NUMERIC, name)) != nullptr) break;
  if (found == nullptr || std::strcmp(std::localeconv()->decimal_point, ",") != 0) {
    std::setlocale(LC_NUMERIC, saved.c_str());
    GTEST_SKIP() << "no locale with a decimal comma is installed";
  }
  TempDir dir;
  const std::string path = dir.file("traj.txt");
  write_file(path, "1.5 2.25 -0.125 0 0 0 0 1\n");
  PoseFile f;
  std::string what;
  try {
    f = vasco::read_pose_file(path);
  } catch (const std::exception &e) {
    what = e.what();
  }
  std::setlocale(LC_NUMERIC, saved.c_str());
  ASSERT_EQ(what, "");
  ASSERT_EQ(f.poses.size(), 1u);
  EXPECT_EQ(f.poses[0].stamp, 1.5);
  EXPECT_EQ(f.poses[0].pose.x, 2.25);
  EXPECT_EQ(f.poses[0].pose.y, -0.125);
}

// ---------------------------------------------------------------------------
// Names.

TEST(PoseFileNames, Formats) {
  EXPECT_EQ(vasco::pose_file_format_from_name("auto"), PoseFileFormat::Auto);
  EXPECT_EQ(vasco::pose_file_format_from_name("tum"), PoseFileFormat::Tum);
  EXPECT_EQ(vasco::pose_file_format_from_name("g2o"), PoseFileFormat::G2o);
  EXPECT_EQ(vasco::pose_file_format_from_name("carmen"), PoseFileFormat::CarmenLog);
  EXPECT_STREQ(vasco::pose_file_format_name(PoseFileFormat::Auto), "auto");
  EXPECT_STREQ(vasco::pose_file_format_name(PoseFileFormat::Tum), "tum");
  EXPECT_STREQ(vasco::pose_file_format_name(PoseFileFormat::G2o), "g2o");
  EXPECT_STREQ(vasco::pose_file_format_name(PoseFileFormat::CarmenLog), "carmen");
  const std::string what = error_of([] { vasco::pose_file_format_from_name("kitti"); }, ErrorCode::Usage);
  EXPECT_CONTAINS(what, "'kitti'");
  EXPECT_CONTAINS(what, "expected one of auto, tum, g2o, carmen");
}

TEST(PoseIdMap, Read) {
  TempDir dir;
  const std::string path = dir.file("ids.txt");
  write_file(path, "# vertex scan\n\n0 12\n  5\t3\r\n+7 0\n");
  const auto map = vasco::read_pose_id_map(path);
  ASSERT_EQ(map.size(), 3u);
  EXPECT_EQ(map[0], std::make_pair(0L, 12L));
  EXPECT_EQ(map[1], std::make_pair(5L, 3L));
  EXPECT_EQ(map[2], std::make_pair(7L, 0L));
}

TEST(PoseIdMap, ReadErrors) {
  TempDir dir;
  const auto map_error = [&](const std::string &text) {
    const std::string path = dir.file("ids.map");
    write_file(path, text);
    return std::make_pair(path, error_of([&] { vasco::read_pose_id_map(path); }, ErrorCode::BadInput));
  };
  auto e = map_error("0 1\n1 x\n");
  EXPECT_CONTAINS(e.second, e.first + ":2: field 2 ('x') is not an integer");
  e = map_error("0 1\n1 2.5\n");
  EXPECT_CONTAINS(e.second, e.first + ":2: field 2 ('2.5') is not an integer");
  e = map_error("0 1\n1 2 3\n");
  EXPECT_CONTAINS(e.second, e.first + ":2: 3 fields, expected 2: 'id scan'");
  e = map_error("-1 1\n");
  EXPECT_CONTAINS(e.second, e.first + ":1: field 1 ('-1') is negative");
  e = map_error("4 1\n# again\n4 2\n");
  EXPECT_CONTAINS(e.second, e.first + ":3: id 4 repeated (first at line 1)");
  e = map_error("99999999999999999999 1\n");
  EXPECT_CONTAINS(e.second, e.first + ":1: field 1 ('99999999999999999999') is out of range");
  e = map_error("# empty\n");
  EXPECT_CONTAINS(e.second, e.first + ": no 'id scan' lines");
}

}  // namespace
