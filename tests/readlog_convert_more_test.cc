// CARMEN's readlog C API (carmen/readlog.h): the converters CARMEN's
// programs call besides the laser and odometry ones (playback, logtool).
#include "carmen/readlog.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "readlog_test_support.h"

namespace {

using readlogtest::buffer;

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

}  // namespace
