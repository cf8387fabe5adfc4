// Tests of the pose files of SLAM back ends and their matching to scans
// (vasco_gpu/pose_file.h). Expected values are worked out by hand here, not
// taken from the code under test.
#include "vasco_gpu/pose_file.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <clocale>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "temp_dir.h"

namespace {

using carmen::ErrorCode;
using vasco::Pose2;
using vasco::PoseFile;
using vasco::PoseFileFormat;
using vasco::PoseMatch;
using vasco::PoseMatching;
using vasco::PoseMatchOptions;
using vasco::StampedPose;

constexpr double kPi = 3.14159265358979323846;

void write_file(const std::string &path, const std::string &text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// "%.17g": enough digits for any double to read back as itself.
std::string g17(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The what() of the carmen::Error that f throws, checked to have `code`;
// "" (and a failure) when it throws none.
std::string error_of(const std::function<void()> &f, ErrorCode code) {
  try {
    f();
  } catch (const carmen::Error &e) {
    EXPECT_EQ(carmen::error_code_name(e.code()), std::string(carmen::error_code_name(code))) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "' lacks '" << (part) << "'"

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

// A quaternion with roll and pitch: its yaw is the Z of Z-Y-X Euler angles.
TEST(PoseFileRead, YawOfAQuaternionWithRollAndPitch) {
  const double roll = 0.1, pitch = 0.2, yaw = 0.7;
  const double cr = std::cos(roll / 2), sr = std::sin(roll / 2), cp = std::cos(pitch / 2), sp = std::sin(pitch / 2),
               cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
  // q = qz(yaw) * qy(pitch) * qx(roll), written out.
  const double qw = cr * cp * cy + sr * sp * sy, qx = sr * cp * cy - cr * sp * sy, qy = cr * sp * cy + sr * cp * sy,
               qz = cr * cp * sy - sr * sp * cy;
  EXPECT_NEAR(vasco::yaw_of_quaternion(qx, qy, qz, qw), yaw, 1e-14);
  EXPECT_NEAR(vasco::yaw_of_quaternion(3 * qx, 3 * qy, 3 * qz, 3 * qw), yaw, 1e-14);  // normalised first
  EXPECT_TRUE(std::isnan(vasco::yaw_of_quaternion(0, 0, 0, 0)));
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

TEST(PoseFileNames, Matchings) {
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

TEST(PoseMatch, ReadPoseIdMap) {
  TempDir dir;
  const std::string path = dir.file("ids.txt");
  write_file(path, "# vertex scan\n\n0 12\n  5\t3\r\n+7 0\n");
  const auto map = vasco::read_pose_id_map(path);
  ASSERT_EQ(map.size(), 3u);
  EXPECT_EQ(map[0], std::make_pair(0L, 12L));
  EXPECT_EQ(map[1], std::make_pair(5L, 3L));
  EXPECT_EQ(map[2], std::make_pair(7L, 0L));
}

TEST(PoseMatch, ReadPoseIdMapErrors) {
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

// ---------------------------------------------------------------------------
// Rigid-body algebra.

TEST(PoseAlgebra, ComposeAndInverse) {
  // theta = 0: a plain translation, exact.
  Pose2 c = vasco::compose({1, 2, 0}, {3, 4, 0.5});
  EXPECT_EQ(c.x, 4);
  EXPECT_EQ(c.y, 6);
  EXPECT_EQ(c.theta, 0.5);
  // A quarter turn: b's x goes to +y, its y to -x: (1 - 4, 2 + 3).
  c = vasco::compose({1, 2, kPi / 2}, {3, 4, 0.5});
  EXPECT_NEAR(c.x, -3, 1e-15);
  EXPECT_NEAR(c.y, 5, 1e-15);
  EXPECT_EQ(c.theta, kPi / 2 + 0.5);
  // No angle normalisation.
  EXPECT_EQ(vasco::compose({0, 0, 3}, {0, 0, 3}).theta, 6);
  // inverse of (1, 2, pi/2): (-cos*1 - sin*2, sin*1 - cos*2, -pi/2) = (-2, 1, -pi/2).
  const Pose2 a = {1, 2, kPi / 2};
  const Pose2 ia = vasco::inverse(a);
  EXPECT_NEAR(ia.x, -2, 1e-15);
  EXPECT_NEAR(ia.y, 1, 1e-15);
  EXPECT_EQ(ia.theta, -kPi / 2);
  const Pose2 id = vasco::compose(a, ia);
  EXPECT_NEAR(id.x, 0, 1e-15);
  EXPECT_NEAR(id.y, 0, 1e-15);
  EXPECT_EQ(id.theta, 0);
  const Pose2 b = {-0.7, 3.25, -2.5};
  const Pose2 id2 = vasco::compose(vasco::inverse(b), b);
  EXPECT_NEAR(id2.x, 0, 1e-14);  // a few roundings of values near 2
  EXPECT_NEAR(id2.y, 0, 1e-14);
  EXPECT_EQ(id2.theta, 0);
}

}  // namespace
