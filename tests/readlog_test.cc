// Tests of CARMEN's readlog C API (carmen/readlog.h), against the C++ reader:
// the laser, odometry and raw laser converters. The other converters:
// readlog_convert_more_test.cc; the log index: readlog_index_test.cc.
#include "carmen/readlog.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "carmen_compat/log_reader.h"
#include "readlog_test_support.h"

namespace {

using readlogtest::bad_log;
using readlogtest::buffer;

constexpr double kPi = 3.14159265358979323846;

std::string bundled_log(const std::string &name) { return std::string(VASCO_LOGS_DIR) + "/" + name; }
std::string shared_data() { return std::string(VASCO_SHARED_DIR) + "/data"; }
bool exists(const std::string &p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

// Frees what the converters realloc()ed.
struct RobotLaser {
  carmen_robot_laser_message m;
  RobotLaser() { std::memset(&m, 0, sizeof m); }
  ~RobotLaser() {
    std::free(m.range);
    std::free(m.tooclose);
    std::free(m.remission);
    std::free(m.host);
  }
};
struct LaserLaser {
  carmen_laser_laser_message m;
  LaserLaser() { std::memset(&m, 0, sizeof m); }
  ~LaserLaser() {
    std::free(m.range);
    std::free(m.remission);
    std::free(m.host);
  }
};
struct Odometry {
  carmen_base_odometry_message m;
  Odometry() { std::memset(&m, 0, sizeof m); }
  ~Odometry() { std::free(m.host); }
};


void expect_same_laser(const carmen_robot_laser_message &c, const carmen::LaserMessage &l) {
  ASSERT_EQ(c.num_readings, static_cast<int>(l.range.size()));
  EXPECT_EQ(std::memcmp(c.range, l.range.data(), sizeof(float) * l.range.size()), 0);
  EXPECT_EQ(c.num_remissions, static_cast<int>(l.remission.size()));
  EXPECT_EQ(c.config.start_angle, l.config.start_angle);
  EXPECT_EQ(c.config.fov, l.config.fov);
  EXPECT_EQ(c.config.angular_resolution, l.config.angular_resolution);
  EXPECT_EQ(c.config.maximum_range, l.config.maximum_range);
  EXPECT_EQ(c.config.accuracy, l.config.accuracy);
  EXPECT_EQ(static_cast<int>(c.config.laser_type), l.config.laser_type);
  EXPECT_EQ(c.laser_pose.x, l.laser_pose.x);
  EXPECT_EQ(c.laser_pose.y, l.laser_pose.y);
  EXPECT_EQ(c.laser_pose.theta, l.laser_pose.theta);
  EXPECT_EQ(c.robot_pose.x, l.robot_pose.x);
  EXPECT_EQ(c.robot_pose.theta, l.robot_pose.theta);
  EXPECT_EQ(c.tv, l.tv);
  EXPECT_EQ(c.turn_axis, l.turn_axis);
  EXPECT_EQ(c.timestamp, l.timestamp);
  EXPECT_STREQ(c.host, l.host.c_str());
}

// Walks a log with the index + converters and compares every FLASER,
// ROBOTLASER1, RAWLASER1 and ODOM with the C++ reader's messages.
void compare_c_and_cpp(const std::string &path, long expect_lasers) {
  SCOPED_TRACE(path);
  carmen_FILE *fp = carmen_fopen(path.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p index = carmen_logfile_index_messages(fp);
  ASSERT_NE(index, nullptr) << carmen_readlog_last_error();

  carmen::LogReader reader(path);
  carmen::LogMessage cpp;
  std::vector<char> line(100000);
  RobotLaser robot;
  LaserLaser raw;
  Odometry odom;
  long lasers = 0, lines = 0;
  while (!carmen_logfile_eof(index)) {
    const int n = carmen_logfile_read_next_line(index, fp, static_cast<int>(line.size()), line.data());
    ASSERT_GT(n, 0) << carmen_readlog_last_error();
    ++lines;
    char *s = line.data();
    const bool flaser = std::strncmp(s, "FLASER ", 7) == 0;
    const bool robotlaser = std::strncmp(s, "ROBOTLASER1 ", 12) == 0;
    const bool rawlaser = std::strncmp(s, "RAWLASER1 ", 10) == 0;
    const bool is_odom = std::strncmp(s, "ODOM ", 5) == 0;
    if (!flaser && !robotlaser && !rawlaser && !is_odom) continue;
    // The C++ reader's next message of these kinds is the same line.
    do {
      ASSERT_TRUE(reader.next(cpp));
    } while (cpp.type != carmen::MessageType::FLASER && cpp.type != carmen::MessageType::ROBOTLASER1 &&
             cpp.type != carmen::MessageType::RAWLASER1 && cpp.type != carmen::MessageType::ODOM);
    ASSERT_EQ(cpp.line, lines);
    char *ret = nullptr;
    if (flaser) {
      ret = carmen_string_to_robot_laser_message_orig(s, &robot.m);
      ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
      expect_same_laser(robot.m, cpp.laser);
      EXPECT_EQ(robot.m.id, 0);  // left as it was (CARMEN's old converter does not set it)
      EXPECT_EQ(std::atof(ret), cpp.laser.logger_timestamp);
      ++lasers;
    } else if (robotlaser) {
      ret = carmen_string_to_robot_laser_message(s, &robot.m);
      ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
      expect_same_laser(robot.m, cpp.laser);
      EXPECT_EQ(robot.m.id, 1);
      EXPECT_EQ(std::atof(ret), cpp.laser.logger_timestamp);
      ++lasers;
    } else if (rawlaser) {
      ret = carmen_string_to_laser_laser_message(s, &raw.m);
      ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
      EXPECT_EQ(raw.m.id, 1);
      ASSERT_EQ(raw.m.num_readings, static_cast<int>(cpp.laser.range.size()));
      EXPECT_EQ(std::memcmp(raw.m.range, cpp.laser.range.data(), 4 * cpp.laser.range.size()), 0);
      EXPECT_EQ(raw.m.config.fov, cpp.laser.config.fov);
      EXPECT_EQ(raw.m.timestamp, cpp.laser.timestamp);
      EXPECT_STREQ(raw.m.host, cpp.laser.host.c_str());
      ++lasers;
    } else {
      ret = carmen_string_to_base_odometry_message(s, &odom.m);
      ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
      EXPECT_EQ(odom.m.x, cpp.odom.x);
      EXPECT_EQ(odom.m.theta, cpp.odom.theta);
      EXPECT_EQ(odom.m.acceleration, cpp.odom.acceleration);
      EXPECT_EQ(odom.m.timestamp, cpp.odom.timestamp);
      EXPECT_STREQ(odom.m.host, cpp.odom.host.c_str());
    }
    if (::testing::Test::HasFatalFailure()) break;
  }
  EXPECT_EQ(lasers, expect_lasers);
  EXPECT_FALSE(reader.next(cpp));  // the C++ reader has nothing left either
  EXPECT_EQ(static_cast<uint64_t>(lines), reader.stats().lines);
  EXPECT_FLOAT_EQ(carmen_logfile_percent_read(index), 1.0f);
  carmen_logfile_free_index(&index);
  EXPECT_EQ(index, nullptr);
  carmen_fclose(fp);
}

TEST(ReadlogCompare, BundledFr079) {
  compare_c_and_cpp(bundled_log("fr079-complete.gfs.log.gz"), 4791);
}

TEST(ReadlogCompare, RobotLaserAndRawLaserLog) {
  const std::string path = shared_data() + "/csail-newcarmen.log.gz";
  if (!exists(path)) GTEST_SKIP() << "shared data set absent (" << path << "); CI has it";
  compare_c_and_cpp(path, 1988 * 2);
}

TEST(ReadlogGuess, MatchesCarmensExpressions) {
  EXPECT_EQ(carmen_laser_guess_fov(181), kPi);
  EXPECT_EQ(carmen_laser_guess_fov(180), kPi / 180.0 * 179.0);
  EXPECT_EQ(carmen_laser_guess_fov(361), kPi);
  EXPECT_EQ(carmen_laser_guess_fov(360), kPi / 180.0 * 179.5);
  EXPECT_EQ(carmen_laser_guess_fov(401), kPi / 180.0 * 100.0);
  EXPECT_EQ(carmen_laser_guess_fov(400), kPi / 100.0 * 99.75);
  EXPECT_EQ(carmen_laser_guess_fov(7), kPi);
  EXPECT_EQ(carmen_laser_guess_angle_increment(181), kPi / 180.0);
  EXPECT_EQ(carmen_laser_guess_angle_increment(180), kPi / 180.0);
  EXPECT_EQ(carmen_laser_guess_angle_increment(361), kPi / 360.0);
  EXPECT_EQ(carmen_laser_guess_angle_increment(360), kPi / 360.0);
  EXPECT_EQ(carmen_laser_guess_angle_increment(401), kPi / 720.0);
  EXPECT_EQ(carmen_laser_guess_angle_increment(400), kPi / 720.0);
  EXPECT_EQ(carmen_laser_guess_angle_increment(7), kPi / 6.0);
}

TEST(ReadlogConvert, NameOptionalIdAndReturnPointer) {
  RobotLaser r;
  std::vector<char> a = buffer(
      "ROBOTLASER2 0 -1.570796 3.141593 0.785398 81.900000 0.010000 2 5 1.00 2.00 3.00 4.00 5.00 2 "
      "0.5 0.25 1.0 2.0 0.5 1.1 2.1 0.6 0.3 0.0 0.3 0.1 1000000.000000 999.5 myhost 0.75\n");
  char *ret = carmen_string_to_robot_laser_message(a.data(), &r.m);
  ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
  EXPECT_EQ(r.m.id, 2);
  EXPECT_EQ(r.m.num_readings, 5);
  EXPECT_EQ(r.m.range[4], 5.0f);
  EXPECT_EQ(r.m.num_remissions, 2);
  EXPECT_EQ(r.m.remission[1], 0.25f);
  EXPECT_EQ(r.m.tooclose[0], 0);
  EXPECT_EQ(r.m.config.remission_mode, REMISSION_NORMALIZED);
  EXPECT_EQ(r.m.laser_pose.x, 1.0);
  EXPECT_EQ(r.m.robot_pose.theta, 0.6);
  EXPECT_EQ(r.m.turn_axis, 1000000.0);
  EXPECT_STREQ(r.m.host, "myhost");
  EXPECT_STREQ(ret, " 0.75\n");  // just past the host, as CARMEN returns

  // Without the name: id -1, same fields.
  std::vector<char> b = buffer(
      "0 -1.570796 3.141593 0.785398 81.900000 0.010000 0 3 1.00 2.00 3.00 0 "
      "1.0 2.0 0.5 1.1 2.1 0.6 0.3 0.0 0.3 0.1 1000000.000000 999.5 h2 0.75");
  ret = carmen_string_to_robot_laser_message(b.data(), &r.m);
  ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
  EXPECT_EQ(r.m.id, -1);
  EXPECT_EQ(r.m.num_readings, 3);  // arrays shrank (realloc)
  EXPECT_EQ(r.m.num_remissions, 0);
  EXPECT_EQ(r.m.remission, nullptr);
  EXPECT_STREQ(r.m.host, "h2");

  // FLASER, with and without its name.
  std::vector<char> c = buffer("FLASER 4 1.0 2.0 3.0 4.0 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5\n");
  ret = carmen_string_to_robot_laser_message_orig(c.data(), &r.m);
  ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
  EXPECT_EQ(r.m.num_readings, 4);
  EXPECT_EQ(r.m.laser_pose.y, 0.2);
  EXPECT_EQ(r.m.robot_pose.x, 1.1);
  EXPECT_EQ(r.m.config.angular_resolution, kPi / 3.0);
  EXPECT_EQ(r.m.config.start_angle, -kPi / 2.0);
  EXPECT_EQ(r.m.config.maximum_range, 80.0);
  EXPECT_EQ(r.m.config.laser_type, SICK_LMS);
  EXPECT_EQ(r.m.tv, 0.3);  // left as the ROBOTLASER1 above set it, as CARMEN's old converter does
  EXPECT_EQ(r.m.num_remissions, 0);
  EXPECT_EQ(std::atof(ret), 1.5);
  std::vector<char> d = buffer("4 1.0 2.0 3.0 4.0 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5");
  // CARMEN's old converter leaves id, tv, rv, the safety distances and
  // turn_axis as they were.
  r.m.id = 7;
  r.m.tv = 0.5;
  r.m.rv = -0.25;
  r.m.forward_safety_dist = 1.5;
  r.m.side_safety_dist = 2.5;
  r.m.turn_axis = 3.5;
  ASSERT_NE(carmen_string_to_robot_laser_message_orig(d.data(), &r.m), nullptr);
  EXPECT_EQ(r.m.id, 7);
  EXPECT_EQ(r.m.tv, 0.5);
  EXPECT_EQ(r.m.rv, -0.25);
  EXPECT_EQ(r.m.forward_safety_dist, 1.5);
  EXPECT_EQ(r.m.side_safety_dist, 2.5);
  EXPECT_EQ(r.m.turn_axis, 3.5);
  EXPECT_EQ(r.m.laser_pose.y, 0.2);

  // RAWLASER and the old LASERn lines.
  LaserLaser l;
  std::vector<char> e = buffer(
      "RAWLASER3 2 -2.094395 4.188790 0.006136 5.600000 0.010000 0 3 1.0 2.0 3.0 0 10.0 urg 0.5\n");
  ret = carmen_string_to_laser_laser_message(e.data(), &l.m);
  ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
  EXPECT_EQ(l.m.id, 3);
  EXPECT_EQ(l.m.config.laser_type, HOKUYO_URG);
  EXPECT_EQ(l.m.config.maximum_range, 5.6);
  EXPECT_EQ(l.m.num_readings, 3);
  EXPECT_STREQ(l.m.host, "urg");
  std::vector<char> f = buffer("LASER4 3 1.5 2.5 3.5 10.0 old 0.5\n");
  ret = carmen_string_to_laser_laser_message_orig(f.data(), &l.m);
  ASSERT_NE(ret, nullptr) << carmen_readlog_last_error();
  EXPECT_EQ(l.m.id, 4);
  EXPECT_EQ(l.m.range[2], 3.5f);
  EXPECT_EQ(l.m.config.angular_resolution, kPi / 2.0);
  EXPECT_STREQ(l.m.host, "old");
  ASSERT_NE(carmen_string_to_laser_laser_message_orig(c.data(), &l.m), nullptr);  // FLASER
  EXPECT_EQ(l.m.num_readings, 4);
  EXPECT_EQ(l.m.id, -1);

  // ODOM and TRUEPOS.
  Odometry o;
  std::vector<char> g = buffer("ODOM 1.5 2.5 0.5 0.3 0.1 0.0 12.0 robot 1.0\n");
  ret = carmen_string_to_base_odometry_message(g.data(), &o.m);
  ASSERT_NE(ret, nullptr);
  EXPECT_EQ(o.m.y, 2.5);
  EXPECT_EQ(o.m.rv, 0.1);
  EXPECT_STREQ(o.m.host, "robot");
  carmen_simulator_truepos_message t;
  std::memset(&t, 0, sizeof t);
  std::vector<char> h = buffer("TRUEPOS 1 2 3 4 5 6 7.5 sim 0.5");
  ASSERT_NE(carmen_string_to_simulator_truepos_message(h.data(), &t), nullptr);
  EXPECT_EQ(t.truepose.theta, 3.0);
  EXPECT_EQ(t.odometrypose.x, 4.0);
  EXPECT_EQ(t.timestamp, 7.5);
  std::free(t.host);
}

// What CARMEN's callers need of a refused line (readlog.h): an empty
// message, a malloc()ed "" host, and a pointer to the line's end (CARMEN's
// playback reads the logger timestamp there).
void expect_empty_robot_laser(const carmen_robot_laser_message &m) {
  EXPECT_EQ(m.num_readings, 0);
  EXPECT_EQ(m.range, nullptr);
  EXPECT_EQ(m.tooclose, nullptr);
  EXPECT_EQ(m.num_remissions, 0);
  EXPECT_EQ(m.remission, nullptr);
  EXPECT_EQ(m.laser_pose.x, 0.0);
  EXPECT_EQ(m.robot_pose.theta, 0.0);
  EXPECT_EQ(m.config.fov, 0.0);
  EXPECT_EQ(m.timestamp, 0.0);
  ASSERT_NE(m.host, nullptr);
  EXPECT_STREQ(m.host, "");
}

TEST(ReadlogConvert, BadLinesLeaveAnEmptyUsableMessage) {
  RobotLaser r;
  std::vector<char> good = buffer("FLASER 3 1.0 2.0 3.0 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5");
  ASSERT_NE(carmen_string_to_robot_laser_message_orig(good.data(), &r.m), nullptr);
  EXPECT_STREQ(carmen_readlog_last_error(), "");

  const char *bad[] = {
      "FLASER 3 1.0 2.0",                                               // truncated
      "FLASER 4 1.0 2.0 3.0 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5",       // count > fields
      "FLASER 2 1.0 2.0 3.0 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5",       // count < fields
      "FLASER 3 1.0 zz 3.0 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5",        // not a number
      "FLASER -3 1.0 2.0 3.0 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5",      // negative count
      "FLASER 999999999 1.0 2.0 3.0 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5",  // absurd count
      "FLASER 3 1.0 2.0 3.0 nan 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5",       // NaN pose
      "FLASER 3 1.0 2.0 3.0 0.1 0.2 0.3 1.1 1.2 1.3 inf hh 1.5",        // inf timestamp
      "",                                                               // empty
  };
  for (const char *s : bad) {
    SCOPED_TRACE(s);
    std::vector<char> b = buffer(std::string(s) + "\nNEXT");
    char *ret = carmen_string_to_robot_laser_message_orig(b.data(), &r.m);
    ASSERT_NE(ret, nullptr);
    EXPECT_EQ(ret, b.data() + std::strlen(s));  // at the '\n'
    EXPECT_EQ(std::atof(ret), 0.0);
    EXPECT_STRNE(carmen_readlog_last_error(), "");
    expect_empty_robot_laser(r.m);
    // And a good line after a bad one is whole again.
    ASSERT_NE(carmen_string_to_robot_laser_message_orig(good.data(), &r.m), nullptr);
    EXPECT_EQ(r.m.num_readings, 3);
    EXPECT_EQ(r.m.range[2], 3.0f);
    EXPECT_STREQ(r.m.host, "hh");
  }
  // NaN / negative ranges are data.
  std::vector<char> odd = buffer("FLASER 3 nan -1.0 inf 0.1 0.2 0.3 1.1 1.2 1.3 50.0 hh 1.5");
  ASSERT_NE(carmen_string_to_robot_laser_message_orig(odd.data(), &r.m), nullptr);
  EXPECT_TRUE(std::isnan(r.m.range[0]));
  EXPECT_EQ(r.m.range[1], -1.0f);

  Odometry o;
  std::vector<char> b1 = buffer("ODOM 1.5 2.5 0.5 0.3 0.1 12.0 robot 1.0");  // a field missing
  char *end1 = carmen_string_to_base_odometry_message(b1.data(), &o.m);
  EXPECT_EQ(end1, b1.data() + b1.size() - 1);  // at the NUL
  EXPECT_NE(std::string(carmen_readlog_last_error()).find("truncated"), std::string::npos)
      << carmen_readlog_last_error();
  ASSERT_NE(o.m.host, nullptr);
  EXPECT_STREQ(o.m.host, "");
  EXPECT_EQ(o.m.x, 0.0);
  LaserLaser l;
  std::vector<char> b2 = buffer("RAWLASERx 0 0 0 0 0 0 0 0 0 1 h 2");
  EXPECT_NE(carmen_string_to_laser_laser_message(b2.data(), &l.m), nullptr);
  EXPECT_NE(std::string(carmen_readlog_last_error()).find("laser number"), std::string::npos);
  EXPECT_EQ(l.m.num_readings, 0);
  EXPECT_STREQ(l.m.host, "");
  // NULL arguments: NULL (and an emptied message where there is one).
  EXPECT_EQ(carmen_string_to_laser_laser_message(nullptr, &l.m), nullptr);
  EXPECT_STREQ(l.m.host, "");
  EXPECT_EQ(carmen_string_to_robot_laser_message(good.data(), nullptr), nullptr);
}

// clf-get-oldlaser's pattern: a static message reused for every
// ROBOTLASER1 line, the return value unchecked, the host strncpy()ed.
TEST(ReadlogConvert, AHugeRemissionCountLeavesAMessageCarmensToolsCanUse) {
  static carmen_robot_laser_message laser;  // zeroed once, as in CARMEN's tools
  const std::string good = "ROBOTLASER1 0 -1.5708 3.14159 0.0174533 81.9 0.01 0 3 1.0 2.0 3.0 0 "
                           "0.1 0.2 0.3 1.1 1.2 1.3 0.5 0.1 0.3 0.1 1000000 7.5 host 1.25";
  const std::string huge = "ROBOTLASER1 0 -1.5708 3.14159 0.0174533 81.9 0.01 0 3 1.0 2.0 3.0 2000000000 "
                           "0.1 0.2 0.3 1.1 1.2 1.3 0.5 0.1 0.3 0.1 1000000 7.5 host 1.25";
  const std::string lines[] = {good, huge, huge, good};
  for (const std::string &s : lines) {
    std::vector<char> b = buffer(s + "\n");
    carmen_string_to_robot_laser_message(b.data(), &laser);
    char host[64];
    ASSERT_NE(laser.host, nullptr);
    std::strncpy(host, laser.host, sizeof host - 1);
    host[sizeof host - 1] = '\0';
    float sum = 0;
    for (int j = 0; j < laser.num_readings; ++j) sum += laser.range[j];
    if (&s == &lines[1] || &s == &lines[2]) {
      EXPECT_NE(std::string(carmen_readlog_last_error()).find("num_remissions 2000000000 exceeds the limit"),
                std::string::npos)
          << carmen_readlog_last_error();
      EXPECT_STREQ(host, "");
      EXPECT_EQ(laser.num_readings, 0);
      EXPECT_EQ(laser.num_remissions, 0);
      EXPECT_EQ(laser.remission, nullptr);
    } else {
      EXPECT_STREQ(host, "host");
      EXPECT_EQ(sum, 6.0f);
      EXPECT_EQ(laser.id, 1);
    }
  }
  std::free(laser.range);
  std::free(laser.tooclose);
  std::free(laser.remission);
  std::free(laser.host);
}

}  // namespace
