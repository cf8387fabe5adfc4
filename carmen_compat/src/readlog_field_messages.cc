// CARMEN's readlog converters of the messages the C++ log reader does not
// parse (ARM, SONAR, BUMPER, BASEVELOCITY, NMEAGGA, NMEARMC, IMU,
// POSITIONLASER, SCANMARK, FOLLOWTRAJECTORY, VECTORMOVE, ROBOTVELOCITY),
// read with its field parser (readlog_convert.h): a message of scalars from
// a table of its fields, one with arrays field by field. A bad line leaves
// an empty, usable message (readlog.h).
#include "carmen/readlog.h"

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "readlog_convert.h"

namespace {

using namespace carmen::readlog;

// DDMM.MMMM to degrees, as CARMEN's converters do (the sign is the value's;
// the orientation letter is not applied).
double degmin_to_degrees(double dm) {
  const double degrees = std::floor(dm / 100.0);
  return degrees + (dm - degrees * 100.0) / 60.0;
}

// An NMEA sentence's position in degrees, from its DDMM.MMMM fields.
template <typename Gps>
void gps_degrees(Gps *m) {
  m->latitude = degmin_to_degrees(m->latitude_dm);
  m->longitude = degmin_to_degrees(m->longitude_dm);
}

}  // namespace

extern "C" {

char *carmen_string_to_arm_state_message(char *string, carmen_arm_state_message *arm) {
  return convert(__func__, string, arm, [](char *str, carmen_arm_state_message *out) -> const char * {
    Fields f(str, "ARM", {"ARM"});
    int flags = 0, gripper = 0, nj = 0, nc = 0, nv = 0;
    std::vector<double> joints, currents, vels;
    if (!f.p.small_int(flags, "flags") || !f.p.count(nj, "num_joints") || !f.doubles(joints, nj, "joint_angles") ||
        !f.p.count(nc, "num_currents") || !f.doubles(currents, nc, "joint_currents") ||
        !f.p.count(nv, "num_vels") || !f.doubles(vels, nv, "joint_angular_vels") ||
        !f.p.small_int(gripper, "gripper_closed") || !f.trailer())
      return f.failed();
    if (!store(&out->joint_angles, out->num_joints, joints) ||
        !store(&out->joint_currents, out->num_currents, currents) ||
        !store(&out->joint_angular_vels, out->num_vels, vels) || !f.host_to(&out->host))
      return out_of_memory();
    out->flags = flags;
    out->num_joints = nj;
    out->num_currents = nc;
    out->num_vels = nv;
    out->gripper_closed = gripper;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_base_sonar_message(char *string, carmen_base_sonar_message *sonar) {
  return convert(__func__, string, sonar, [](char *str, carmen_base_sonar_message *out) -> const char * {
    Fields f(str, "SONAR", {"SONAR"});
    double cone = 0;
    int n = 0;
    std::vector<double> ranges, offsets;
    if (!f.p.finite(cone, "cone_angle") || !f.p.count(n, "num_sonars") || !f.doubles(ranges, n, "range") ||
        !f.doubles(offsets, 3 * n, "sonar_offsets", true) || !f.trailer())
      return f.failed();
    std::vector<carmen_point_t> points(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) points[i] = {offsets[3 * i], offsets[3 * i + 1], offsets[3 * i + 2]};
    if (!store(&out->range, out->num_sonars, ranges) || !store(&out->sonar_offsets, out->num_sonars, points) ||
        !f.host_to(&out->host))
      return out_of_memory();
    out->num_sonars = n;
    out->cone_angle = cone;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_base_bumper_message(char *string, carmen_base_bumper_message *bumper) {
  return convert(__func__, string, bumper, [](char *str, carmen_base_bumper_message *out) -> const char * {
    Fields f(str, "BUMPER", {"BUMPER"});
    int n = 0;
    std::vector<unsigned char> states;
    std::vector<double> offsets;
    if (!f.p.count(n, "num_bumpers")) return f.failed();
    for (int i = 0; i < n; ++i) {
      int v = 0;
      if (!f.p.small_int(v, "state")) return f.failed();
      if (v < 0 || v > 255) {
        set_error(std::string("BUMPER state ") + std::to_string(v) + " (field " + std::to_string(f.p.field()) +
                  ") is not 0..255");
        return nullptr;
      }
      states.push_back(static_cast<unsigned char>(v));
    }
    if (!f.doubles(offsets, 2 * n, "bumper_offsets", true) || !f.trailer()) return f.failed();
    std::vector<carmen_position_t> points(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) points[i] = {offsets[2 * i], offsets[2 * i + 1]};
    if (!store(&out->state, out->num_bumpers, states) || !store(&out->bumper_offsets, out->num_bumpers, points) ||
        !f.host_to(&out->host))
      return out_of_memory();
    out->num_bumpers = n;
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_base_velocity_message(char *string, carmen_base_velocity_message *msg) {
  using M = carmen_base_velocity_message;
  static const ScalarField<M> kFields[] = {{"tv", &M::tv}, {"rv", &M::rv}};
  return convert_scalars(__func__, string, msg, {"BASEVELOCITY"}, kFields);
}

char *carmen_string_to_gps_gpgga_message(char *string, carmen_gps_gpgga_message *gps_msg) {
  using M = carmen_gps_gpgga_message;
  static const ScalarField<M> kFields[] = {
      {"nr", &M::nr},
      {"utc", &M::utc},
      {"latitude_dm", &M::latitude_dm},
      {"lat_orient", &M::lat_orient},
      {"longitude_dm", &M::longitude_dm},
      {"long_orient", &M::long_orient},
      {"gps_quality", &M::gps_quality},
      {"num_satellites", &M::num_satellites},
      {"hdop", &M::hdop},
      {"sea_level", &M::sea_level},
      {"altitude", &M::altitude},
      {"geo_sea_level", &M::geo_sea_level},
      {"geo_sep", &M::geo_sep},
      {"data_age", &M::data_age}};
  return convert_scalars(__func__, string, gps_msg, {"NMEAGGA"}, kFields, gps_degrees<M>);
}

char *carmen_string_to_gps_gprmc_message(char *string, carmen_gps_gprmc_message *gps_msg) {
  using M = carmen_gps_gprmc_message;
  static const ScalarField<M> kFields[] = {
      {"nr", &M::nr},
      {"validity", &M::validity},
      {"utc", &M::utc},
      {"latitude_dm", &M::latitude_dm},
      {"lat_orient", &M::lat_orient},
      {"longitude_dm", &M::longitude_dm},
      {"long_orient", &M::long_orient},
      {"speed", &M::speed},
      {"true_course", &M::true_course},
      {"variation", &M::variation},
      {"var_dir", &M::var_dir},
      {"date", &M::date}};
  return convert_scalars(__func__, string, gps_msg, {"NMEARMC"}, kFields, gps_degrees<M>);
}

char *carmen_string_to_imu_message(char *string, carmen_imu_message *msg) {
  using M = carmen_imu_message;
  static const ScalarField<M> kFields[] = {
      {"accX", &M::accX}, {"accY", &M::accY},   {"accZ", &M::accZ},   {"q0", &M::q0},       {"q1", &M::q1},
      {"q2", &M::q2},     {"q3", &M::q3},       {"magX", &M::magX},   {"magY", &M::magY},   {"magZ", &M::magZ},
      {"gyroX", &M::gyroX}, {"gyroY", &M::gyroY}, {"gyroZ", &M::gyroZ}};
  return convert_scalars(__func__, string, msg, {"IMU"}, kFields);
}

char *carmen_string_to_pantilt_laserpos_message(char *string, carmen_pantilt_laserpos_message *laserpos) {
  using M = carmen_pantilt_laserpos_message;
  static const ScalarField<M> kFields[] = {{"id", &M::id},   {"x", &M::x},         {"y", &M::y},    {"z", &M::z},
                                           {"phi", &M::phi}, {"theta", &M::theta}, {"psi", &M::psi}};
  return convert_scalars(__func__, string, laserpos, {"POSITIONLASER"}, kFields);
}

char *carmen_string_to_pantilt_scanmark_message(char *string, carmen_pantilt_scanmark_message *scanmark) {
  using M = carmen_pantilt_scanmark_message;
  static const ScalarField<M> kFields[] = {{"type", &M::type}, {"laserid", &M::laserid}};
  return convert_scalars(__func__, string, scanmark, {"SCANMARK"}, kFields);
}

char *carmen_string_to_robot_follow_trajectory_message(char *string,
                                                       carmen_robot_follow_trajectory_message *msg) {
  return convert(__func__, string, msg,
                 [](char *str, carmen_robot_follow_trajectory_message *out) -> const char * {
    Fields f(str, "FOLLOWTRAJECTORY", {"FOLLOWTRAJECTORY", "ROBOTVELOCITY"});
    double r[5];
    static const char *const kNames[5] = {"x", "y", "theta", "t_vel", "r_vel"};
    for (int i = 0; i < 5; ++i)
      if (!f.p.finite(r[i], kNames[i])) return f.failed();
    int n = 0;
    std::vector<double> pts;
    if (!f.p.count(n, "trajectory_length") || !f.doubles(pts, 5 * n, "trajectory", true) || !f.trailer())
      return f.failed();
    std::vector<carmen_traj_point_t> traj(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      traj[i] = {pts[5 * i], pts[5 * i + 1], pts[5 * i + 2], pts[5 * i + 3], pts[5 * i + 4]};
    if (!store(&out->trajectory, out->trajectory_length, traj) || !f.host_to(&out->host)) return out_of_memory();
    out->trajectory_length = n;
    out->robot_position = {r[0], r[1], r[2], r[3], r[4]};
    out->timestamp = f.timestamp;
    return f.after_host;
  });
}

char *carmen_string_to_robot_vector_move_message(char *string, carmen_robot_vector_move_message *msg) {
  using M = carmen_robot_vector_move_message;
  static const ScalarField<M> kFields[] = {{"distance", &M::distance}, {"theta", &M::theta}};
  return convert_scalars(__func__, string, msg, {"VECTORMOVE"}, kFields);
}

char *carmen_string_to_robot_velocity_message(char *string, carmen_robot_velocity_message *msg) {
  using M = carmen_robot_velocity_message;
  static const ScalarField<M> kFields[] = {{"tv", &M::tv}, {"rv", &M::rv}};
  return convert_scalars(__func__, string, msg, {"ROBOTVELOCITY", "VELOCITY"}, kFields);
}

}  // extern "C"
