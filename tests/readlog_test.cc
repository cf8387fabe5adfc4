// Tests of CARMEN's readlog C API (carmen/readlog.h), against the C++ reader.
#include "carmen/readlog.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zlib.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "carmen_compat/log_reader.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string bad_log(const std::string &name) {
  return std::string(VASCO_TEST_DATA_DIR) + "/logs/" + name;
}
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

std::vector<char> buffer(const std::string &s) {
  std::vector<char> v(s.begin(), s.end());
  v.push_back('\0');
  return v;
}

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

// The other converters CARMEN's programs call (playback, logtool).

void free_all(carmen_arm_state_message &m) {
  std::free(m.joint_angles);
  std::free(m.joint_currents);
  std::free(m.joint_angular_vels);
  std::free(m.host);
}
void free_all(carmen_base_sonar_message &m) {
  std::free(m.range);
  std::free(m.sonar_offsets);
  std::free(m.host);
}
void free_all(carmen_base_bumper_message &m) {
  std::free(m.state);
  std::free(m.bumper_offsets);
  std::free(m.host);
}
void free_all(carmen_robot_follow_trajectory_message &m) {
  std::free(m.trajectory);
  std::free(m.host);
}
template <typename M>
void free_all(M &m) {
  std::free(m.host);
}

// Owns a zeroed message and frees what the converter allocated.
template <typename M>
struct Msg {
  M m;
  Msg() { std::memset(static_cast<void *>(&m), 0, sizeof m); }
  ~Msg() { free_all(m); }
};

// Converts `line` (with "\n" appended); expects success and the return value
// at " logger_timestamp".
template <typename M>
void convert_ok(char *(*conv)(char *, M *), const std::string &line, M *m) {
  std::vector<char> b = buffer(line + "\n");
  char *ret = conv(b.data(), m);
  ASSERT_NE(ret, nullptr);
  EXPECT_STREQ(carmen_readlog_last_error(), "") << line;
  EXPECT_EQ(std::string(ret), " 1.25\n") << line;
  ASSERT_NE(m->host, nullptr);
  EXPECT_STREQ(m->host, "host");
  EXPECT_EQ(m->timestamp, 7.5);
}

// Converts a bad `line`: an error naming it, an empty message, the line's end.
template <typename M>
void convert_bad(char *(*conv)(char *, M *), const std::string &line, M *m, const char *why) {
  SCOPED_TRACE(line);
  std::vector<char> b = buffer(line + "\nNEXT 1 2 3");
  char *ret = conv(b.data(), m);
  ASSERT_NE(ret, nullptr);
  EXPECT_EQ(ret, b.data() + line.size());
  EXPECT_NE(std::string(carmen_readlog_last_error()).find(why), std::string::npos) << carmen_readlog_last_error();
  ASSERT_NE(m->host, nullptr);
  EXPECT_STREQ(m->host, "");
  EXPECT_EQ(m->timestamp, 0.0);
}

// The good line without its last `drop` fields.
std::string cut(const std::string &line, int drop) {
  std::string s = line;
  for (int i = 0; i < drop; ++i) s = s.substr(0, s.rfind(' '));
  return s;
}

TEST(ReadlogConvertMore, ArmState) {
  Msg<carmen_arm_state_message> a;
  const std::string good = "ARM 7 2 0.5 -0.25 1 1.5 0 1 7.5 host 1.25";
  convert_ok(carmen_string_to_arm_state_message, good, &a.m);
  EXPECT_EQ(a.m.flags, 7);
  ASSERT_EQ(a.m.num_joints, 2);
  EXPECT_EQ(a.m.joint_angles[0], 0.5);
  EXPECT_EQ(a.m.joint_angles[1], -0.25);
  ASSERT_EQ(a.m.num_currents, 1);
  EXPECT_EQ(a.m.joint_currents[0], 1.5);
  EXPECT_EQ(a.m.num_vels, 0);
  EXPECT_EQ(a.m.joint_angular_vels, nullptr);
  EXPECT_EQ(a.m.gripper_closed, 1);
  // Without the name, as CARMEN's playback passes it.
  convert_ok(carmen_string_to_arm_state_message, good.substr(4), &a.m);
  EXPECT_EQ(a.m.num_joints, 2);
  for (const auto &[line, why] : std::vector<std::pair<std::string, const char *>>{
           {cut(good, 3), "truncated"},
           {"ARM 7 999999 0.5 -0.25 1 1.5 0 1 7.5 host 1.25", "num_joints 999999 exceeds the limit of 100000"},
           {"ARM 7 -2 0.5 -0.25 1 1.5 0 1 7.5 host 1.25", "num_joints -2 is negative"},
           {"ARM 7 3 0.5 -0.25 1 1.5 0 1 7.5 host 1.25", "ARM"},
           {"ARM x y z", "'x' is not a number"},
       }) {
    convert_bad(carmen_string_to_arm_state_message, line, &a.m, why);
    EXPECT_EQ(a.m.num_joints, 0);
    EXPECT_EQ(a.m.joint_angles, nullptr);
    EXPECT_EQ(a.m.joint_currents, nullptr);
    EXPECT_EQ(a.m.flags, 0);
  }
}

TEST(ReadlogConvertMore, BaseSonarBumperVelocity) {
  Msg<carmen_base_sonar_message> s;
  const std::string sonar = "SONAR 0.5 2 1.25 2.5 0.1 0.2 0.3 -0.1 -0.2 -0.3 7.5 host 1.25";
  convert_ok(carmen_string_to_base_sonar_message, sonar, &s.m);
  EXPECT_EQ(s.m.cone_angle, 0.5);
  ASSERT_EQ(s.m.num_sonars, 2);
  EXPECT_EQ(s.m.range[0], 1.25);
  EXPECT_EQ(s.m.range[1], 2.5);
  EXPECT_EQ(s.m.sonar_offsets[0].x, 0.1);
  EXPECT_EQ(s.m.sonar_offsets[0].theta, 0.3);
  EXPECT_EQ(s.m.sonar_offsets[1].y, -0.2);
  convert_bad(carmen_string_to_base_sonar_message, cut(sonar, 4), &s.m, "truncated");
  EXPECT_EQ(s.m.num_sonars, 0);
  EXPECT_EQ(s.m.range, nullptr);
  EXPECT_EQ(s.m.sonar_offsets, nullptr);
  convert_bad(carmen_string_to_base_sonar_message, "SONAR 0.5 2000000000 1 2 3", &s.m, "exceeds the limit");
  convert_bad(carmen_string_to_base_sonar_message, "SONAR \x01\x02 garbage", &s.m, "is not a number");

  Msg<carmen_base_bumper_message> b;
  const std::string bumper = "BUMPER 2 1 0 0.25 0.5 -0.25 -0.5 7.5 host 1.25";
  convert_ok(carmen_string_to_base_bumper_message, bumper, &b.m);
  ASSERT_EQ(b.m.num_bumpers, 2);
  EXPECT_EQ(b.m.state[0], 1);
  EXPECT_EQ(b.m.state[1], 0);
  EXPECT_EQ(b.m.bumper_offsets[0].x, 0.25);
  EXPECT_EQ(b.m.bumper_offsets[1].y, -0.5);
  convert_bad(carmen_string_to_base_bumper_message, cut(bumper, 5), &b.m, "truncated");
  EXPECT_EQ(b.m.state, nullptr);
  EXPECT_EQ(b.m.bumper_offsets, nullptr);
  convert_bad(carmen_string_to_base_bumper_message, "BUMPER 2 1 300 0.25 0.5 -0.25 -0.5 7.5 host 1.25", &b.m,
              "is not 0..255");
  convert_bad(carmen_string_to_base_bumper_message, "BUMPER 99999999999999999999 1", &b.m, "exceeds the limit");

  Msg<carmen_base_velocity_message> v;
  convert_ok(carmen_string_to_base_velocity_message, "BASEVELOCITY 0.3 -0.1 7.5 host 1.25", &v.m);
  EXPECT_EQ(v.m.tv, 0.3);
  EXPECT_EQ(v.m.rv, -0.1);
  convert_bad(carmen_string_to_base_velocity_message, "BASEVELOCITY 0.3 -0.1 7.5 host", &v.m, "truncated");
  EXPECT_EQ(v.m.tv, 0.0);
  convert_bad(carmen_string_to_base_velocity_message, "BASEVELOCITY 0.3 -0.1 7.5 host 1.25 extra", &v.m,
              "extra field 'extra'");
}

TEST(ReadlogConvertMore, Gps) {
  Msg<carmen_gps_gpgga_message> g;
  const std::string gga = "NMEAGGA 1 123519.000000 4807.038000 N 1131.000000 E 1 8 0.900000 545.400000 "
                          "46.900000 -0.500000 0.250000 3 7.5 host 1.25";
  convert_ok(carmen_string_to_gps_gpgga_message, gga, &g.m);
  EXPECT_EQ(g.m.nr, 1);
  EXPECT_EQ(g.m.utc, 123519.0);
  EXPECT_EQ(g.m.latitude_dm, 4807.038);
  EXPECT_NEAR(g.m.latitude, 48.0 + 7.038 / 60.0, 1e-12);
  EXPECT_EQ(g.m.lat_orient, 'N');
  EXPECT_EQ(g.m.longitude_dm, 1131.0);
  EXPECT_NEAR(g.m.longitude, 11.0 + 31.0 / 60.0, 1e-12);
  EXPECT_EQ(g.m.long_orient, 'E');
  EXPECT_EQ(g.m.gps_quality, 1);
  EXPECT_EQ(g.m.num_satellites, 8);
  EXPECT_EQ(g.m.hdop, 0.9);
  EXPECT_EQ(g.m.sea_level, 545.4);
  EXPECT_EQ(g.m.altitude, 46.9);
  EXPECT_EQ(g.m.geo_sea_level, -0.5);
  EXPECT_EQ(g.m.geo_sep, 0.25);
  EXPECT_EQ(g.m.data_age, 3);
  convert_bad(carmen_string_to_gps_gpgga_message, cut(gga, 6), &g.m, "truncated");
  EXPECT_EQ(g.m.latitude, 0.0);
  EXPECT_EQ(g.m.lat_orient, 0);
  convert_bad(carmen_string_to_gps_gpgga_message,
              "NMEAGGA 1 123519.0 4807.038 North 1131.0 E 1 8 0.9 545.4 46.9 0 0 0 7.5 host 1.25", &g.m,
              "lat_orient (field 4): 'North' is not one character");
  convert_bad(carmen_string_to_gps_gpgga_message, "NMEAGGA nan", &g.m, "nr");

  Msg<carmen_gps_gprmc_message> r;
  const std::string rmc = "NMEARMC 2 1 123519.000000 4807.038000 S 1131.000000 W 0.5 1.25 0.05 W 230394 7.5 host 1.25";
  convert_ok(carmen_string_to_gps_gprmc_message, rmc, &r.m);
  EXPECT_EQ(r.m.nr, 2);
  EXPECT_EQ(r.m.validity, 1);
  EXPECT_NEAR(r.m.latitude, 48.0 + 7.038 / 60.0, 1e-12);  // unsigned, as CARMEN's
  EXPECT_EQ(r.m.lat_orient, 'S');
  EXPECT_EQ(r.m.long_orient, 'W');
  EXPECT_EQ(r.m.speed, 0.5);
  EXPECT_EQ(r.m.true_course, 1.25);
  EXPECT_EQ(r.m.variation, 0.05);
  EXPECT_EQ(r.m.var_dir, 'W');
  EXPECT_EQ(r.m.date, 230394);
  convert_bad(carmen_string_to_gps_gprmc_message, cut(rmc, 2), &r.m, "truncated");
  convert_bad(carmen_string_to_gps_gprmc_message, "NMEARMC 2 1 inf", &r.m, "not finite");
}

TEST(ReadlogConvertMore, ImuAndPantilt) {
  Msg<carmen_imu_message> m;
  const std::string imu = "IMU 0.1 0.2 9.8 1 0 0 0 0.3 0.4 0.5 0.01 0.02 0.03 7.5 host 1.25";
  convert_ok(carmen_string_to_imu_message, imu, &m.m);
  EXPECT_EQ(m.m.accX, 0.1);
  EXPECT_EQ(m.m.accZ, 9.8);
  EXPECT_EQ(m.m.q0, 1.0);
  EXPECT_EQ(m.m.q3, 0.0);
  EXPECT_EQ(m.m.magY, 0.4);
  EXPECT_EQ(m.m.gyroZ, 0.03);
  convert_bad(carmen_string_to_imu_message, cut(imu, 5), &m.m, "truncated");
  EXPECT_EQ(m.m.accZ, 0.0);
  convert_bad(carmen_string_to_imu_message, "IMU 0.1 0.2 zz", &m.m, "accZ (field 3): 'zz' is not a number");

  Msg<carmen_pantilt_laserpos_message> p;
  const std::string pos = "POSITIONLASER 2 0.1 0.2 0.3 0.01 0.02 0.03 7.5 host 1.25";
  convert_ok(carmen_string_to_pantilt_laserpos_message, pos, &p.m);
  EXPECT_EQ(p.m.id, 2);
  EXPECT_EQ(p.m.x, 0.1);
  EXPECT_EQ(p.m.z, 0.3);
  EXPECT_EQ(p.m.phi, 0.01);
  EXPECT_EQ(p.m.psi, 0.03);
  convert_bad(carmen_string_to_pantilt_laserpos_message, cut(pos, 4), &p.m, "truncated");
  EXPECT_EQ(p.m.id, 0);

  Msg<carmen_pantilt_scanmark_message> k;
  convert_ok(carmen_string_to_pantilt_scanmark_message, "SCANMARK 1 2 7.5 host 1.25", &k.m);
  EXPECT_EQ(k.m.type, 1);
  EXPECT_EQ(k.m.laserid, 2);
  convert_bad(carmen_string_to_pantilt_scanmark_message, "SCANMARK 1", &k.m, "truncated");
  convert_bad(carmen_string_to_pantilt_scanmark_message, "SCANMARK 1.5 2 7.5 host 1.25", &k.m, "is not a number");
}

TEST(ReadlogConvertMore, RobotTrajectoryVectorMoveVelocity) {
  Msg<carmen_robot_follow_trajectory_message> t;
  const std::string traj = "FOLLOWTRAJECTORY 1 2 0.5 0.3 0.1 2 3 4 0.6 0.2 0.05 5 6 0.7 0.1 0 7.5 host 1.25";
  convert_ok(carmen_string_to_robot_follow_trajectory_message, traj, &t.m);
  EXPECT_EQ(t.m.robot_position.x, 1.0);
  EXPECT_EQ(t.m.robot_position.theta, 0.5);
  EXPECT_EQ(t.m.robot_position.r_vel, 0.1);
  ASSERT_EQ(t.m.trajectory_length, 2);
  EXPECT_EQ(t.m.trajectory[0].x, 3.0);
  EXPECT_EQ(t.m.trajectory[0].r_vel, 0.05);
  EXPECT_EQ(t.m.trajectory[1].y, 6.0);
  EXPECT_EQ(t.m.trajectory[1].t_vel, 0.1);
  // CARMEN's converter skips "ROBOTVELOCITY" here: so do we.
  convert_ok(carmen_string_to_robot_follow_trajectory_message, "ROBOTVELOCITY" + traj.substr(16), &t.m);
  EXPECT_EQ(t.m.trajectory_length, 2);
  convert_bad(carmen_string_to_robot_follow_trajectory_message, cut(traj, 4), &t.m, "truncated");
  EXPECT_EQ(t.m.trajectory_length, 0);
  EXPECT_EQ(t.m.trajectory, nullptr);
  convert_bad(carmen_string_to_robot_follow_trajectory_message, "FOLLOWTRAJECTORY 1 2 0.5 0.3 0.1 100001 3", &t.m,
              "trajectory_length 100001 exceeds the limit");

  Msg<carmen_robot_vector_move_message> v;
  convert_ok(carmen_string_to_robot_vector_move_message, "VECTORMOVE 1.5 -0.5 7.5 host 1.25", &v.m);
  EXPECT_EQ(v.m.distance, 1.5);
  EXPECT_EQ(v.m.theta, -0.5);
  convert_bad(carmen_string_to_robot_vector_move_message, "VECTORMOVE 1.5", &v.m, "truncated");
  EXPECT_EQ(v.m.distance, 0.0);

  Msg<carmen_robot_velocity_message> r;
  convert_ok(carmen_string_to_robot_velocity_message, "ROBOTVELOCITY 0.3 0.1 7.5 host 1.25", &r.m);
  EXPECT_EQ(r.m.tv, 0.3);
  EXPECT_EQ(r.m.rv, 0.1);
  convert_ok(carmen_string_to_robot_velocity_message, "VELOCITY 0.25 0.1 7.5 host 1.25", &r.m);
  EXPECT_EQ(r.m.tv, 0.25);
  convert_ok(carmen_string_to_robot_velocity_message, "0.2 0.1 7.5 host 1.25", &r.m);
  EXPECT_EQ(r.m.tv, 0.2);
  convert_bad(carmen_string_to_robot_velocity_message, "ROBOTVELOCITY 0.3 0.1 7.5 host 1.25 9", &r.m, "extra");
  convert_bad(carmen_string_to_robot_velocity_message, "", &r.m, "truncated");
  EXPECT_EQ(carmen_string_to_robot_velocity_message(nullptr, &r.m), nullptr);
}

// CARMEN's progress lines, exactly.
TEST(ReadlogIndex, PrintsCarmensProgress) {
  testing::internal::CaptureStderr();
  carmen_FILE *fp = carmen_fopen(bad_log("good.log").c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  const std::string err = testing::internal::GetCapturedStderr();
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(err, "\n\rIndexing messages (0%)    \rIndexing messages (100%) - " + std::to_string(idx->num_messages) +
                     " messages found.      \n");
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);

  // A line every 10 MB (CARMEN: every 1000 reads of 10000 bytes).
  char tmpl[] = "/tmp/vasco_readlog_progress_XXXXXX";
  const int fd = mkstemp(tmpl);
  ASSERT_GE(fd, 0);
  close(fd);
  {
    std::ofstream out(tmpl, std::ios::binary);
    const std::string line(99, 'x');
    for (int i = 0; i < 250000; ++i) out << line << '\n';  // 25 MB
  }
  testing::internal::CaptureStderr();
  fp = carmen_fopen(tmpl, "r");
  ASSERT_NE(fp, nullptr);
  idx = carmen_logfile_index_messages(fp);
  const std::string big = testing::internal::GetCapturedStderr();
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(idx->num_messages, 250000);
  EXPECT_EQ(big, "\n\rIndexing messages (0%)    \rIndexing messages (40%)      \rIndexing messages (80%)      "
                 "\rIndexing messages (100%) - 250000 messages found.      \n");
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
  std::remove(tmpl);
}

TEST(ReadlogIndex, BlankLinesUnterminatedLastLineAndLimits) {
  char tmpl[] = "/tmp/readlog_test_XXXXXX";
  const int fd = mkstemp(tmpl);
  ASSERT_GE(fd, 0);
  close(fd);
  const std::string path = tmpl;
  {
    std::ofstream out(path, std::ios::binary);
    out << "ODOM 1 2 3 0 0 0 5 h 1\n\nFLASER 1 2.0 0 0 0 0 0 0 6 h 2\n\rX\nlast";
  }
  carmen_FILE *fp = carmen_fopen(path.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  // "ODOM...\n", "\n", "FLASER...\n\rX\n" (no message starts at '\r'), "last"
  ASSERT_EQ(idx->num_messages, 4);
  EXPECT_EQ(idx->offset[0], 0);
  EXPECT_EQ(idx->offset[1], 23);
  EXPECT_EQ(idx->offset[2], 24);
  EXPECT_EQ(idx->offset[3], 58);
  EXPECT_EQ(idx->offset[4], 62);
  EXPECT_EQ(carmen_logfile_percent_read(idx), 0.0f);
  char line[128];
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 3, sizeof line, line), 4);  // random access
  EXPECT_STREQ(line, "last");
  EXPECT_TRUE(carmen_logfile_eof(idx));
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 1, sizeof line, line), 1);
  EXPECT_STREQ(line, "\n");
  EXPECT_EQ(carmen_logfile_read_next_line(idx, fp, sizeof line, line), 34);
  EXPECT_EQ(std::strncmp(line, "FLASER 1 2.0", 12), 0);
  EXPECT_EQ(carmen_logfile_percent_read(idx), 0.75f);
  // Limits: a buffer too small, numbers out of range.
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 0, 23, line), -1);
  EXPECT_NE(std::string(carmen_readlog_last_error()).find("23 bytes"), std::string::npos);
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 0, 24, line), 23);
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 4, sizeof line, line), -1);
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, -1, sizeof line, line), -1);
  EXPECT_EQ(carmen_logfile_read_line(nullptr, fp, 0, sizeof line, line), -1);
  carmen_logfile_free_index(&idx);
  carmen_logfile_free_index(&idx);  // harmless twice
  carmen_fclose(fp);
  std::remove(path.c_str());
  EXPECT_EQ(carmen_logfile_index_messages(nullptr), nullptr);
  EXPECT_TRUE(carmen_logfile_eof(nullptr));
}

// CARMEN's own reading loop (vasco-tiny, clf-read-example) must end: on a
// damaged gzip the index holds what came before the damage, and every
// message can be read in sequence until carmen_logfile_eof().
int read_until_eof(carmen_logfile_index_p idx, carmen_FILE *fp, int buffer, int *failures) {
  std::vector<char> line(static_cast<size_t>(buffer));
  int calls = 0;
  *failures = 0;
  while (!carmen_logfile_eof(idx) && calls <= idx->num_messages) {
    if (carmen_logfile_read_next_line(idx, fp, buffer, line.data()) < 0) ++*failures;
    ++calls;
  }
  return calls;
}

TEST(ReadlogIndex, DamagedGzipIndexesWhatCameBefore) {
  for (const char *f : {"truncated.log.gz", "corrupt.log.gz", "bad_crc.log.gz"}) {
    SCOPED_TRACE(f);
    carmen_FILE *fp = carmen_fopen(bad_log(f).c_str(), "r");
    ASSERT_NE(fp, nullptr);
    carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
    ASSERT_NE(idx, nullptr);
    EXPECT_NE(std::string(carmen_readlog_last_error()).find("gzip"), std::string::npos);
    int failures = 0;
    EXPECT_EQ(read_until_eof(idx, fp, 1 << 16, &failures), idx->num_messages);
    EXPECT_TRUE(carmen_logfile_eof(idx));
    carmen_logfile_free_index(&idx);
    carmen_fclose(fp);
  }
  // A good gzip log indexes every line.
  carmen_FILE *fp = carmen_fopen(bad_log("two_members.log.gz").c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(idx->num_messages, 11);
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
}

// A message longer than the caller's buffer is skipped with a message (CARMEN
// exits there); the loop goes on to the end instead of spinning.
TEST(ReadlogIndex, AMessageLongerThanTheBufferIsSkippedNotSpunOn) {
  char tmpl[] = "/tmp/vasco_readlog_XXXXXX";
  const int fd = mkstemp(tmpl);
  ASSERT_GE(fd, 0);
  close(fd);
  {
    std::ofstream out(tmpl, std::ios::binary);
    out << "ODOM 1 2 3 0 0 0 5 h 1\n" << "ODOM " << std::string(500, '1') << "\n" << "ODOM 1 2 3 0 0 0 7 h 3\n";
  }
  carmen_FILE *fp = carmen_fopen(tmpl, "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  ASSERT_EQ(idx->num_messages, 3);
  int failures = 0;
  EXPECT_EQ(read_until_eof(idx, fp, 64, &failures), 3);
  EXPECT_EQ(failures, 1);
  // And the line after the long one was read whole.
  char line[64];
  EXPECT_EQ(carmen_logfile_read_line(idx, fp, 2, sizeof line, line), 23);
  EXPECT_EQ(std::strncmp(line, "ODOM 1 2 3 0 0 0 7", 18), 0);
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
  std::remove(tmpl);
}

}  // namespace

namespace {

// A gzip log of `n` newlines and nothing else (a 204 KB one held 209 M
// messages for CARMEN's rule: an index of 3.3 GB).
std::string newlines_gz(int n) {
  char tmpl[] = "/tmp/vasco_readlog_nl_XXXXXX";
  const int fd = mkstemp(tmpl);
  close(fd);
  const std::string path = std::string(tmpl) + ".gz";
  std::rename(tmpl, path.c_str());
  gzFile out = gzopen(path.c_str(), "wb");
  const std::string block(1 << 16, '\n');
  for (int done = 0; done < n; done += static_cast<int>(block.size()))
    gzwrite(out, block.data(), static_cast<unsigned>(std::min<int>(n - done, static_cast<int>(block.size()))));
  gzclose(out);
  return path;
}

TEST(ReadlogIndex, TheIndexIsBoundedAndSaysSo) {
  EXPECT_EQ(carmen_logfile_set_max_messages(0), CARMEN_LOGFILE_MAX_MESSAGES);  // 0: only asks
  const int before = carmen_logfile_set_max_messages(100000);
  const std::string over = newlines_gz(1000000), at = newlines_gz(100000);
  carmen_FILE *fp = carmen_fopen(over.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  EXPECT_EQ(carmen_logfile_index_messages(fp), nullptr);
  EXPECT_NE(std::string(carmen_readlog_last_error()).find("more than 100000 messages"), std::string::npos)
      << carmen_readlog_last_error();
  carmen_fclose(fp);
  // Exactly the limit is indexed.
  fp = carmen_fopen(at.c_str(), "r");
  ASSERT_NE(fp, nullptr);
  carmen_logfile_index_p idx = carmen_logfile_index_messages(fp);
  ASSERT_NE(idx, nullptr);
  EXPECT_EQ(idx->num_messages, 100000);
  EXPECT_EQ(idx->offset[99999], 99999);
  EXPECT_EQ(idx->offset[100000], 100000);
  carmen_logfile_free_index(&idx);
  carmen_fclose(fp);
  EXPECT_EQ(carmen_logfile_set_max_messages(before), 100000);
  std::remove(over.c_str());
  std::remove(at.c_str());
}

}  // namespace
