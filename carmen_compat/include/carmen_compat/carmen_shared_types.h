/* carmen_shared_types.h — the CARMEN 0.7.4 types that our CARMEN headers
 * (readlog.h, map.h) use but CARMEN itself defines in other headers:
 *   carmen_point_t                      global.h              CARMEN_GLOBAL_H
 *   carmen_laser_laser_config_t,
 *   carmen_laser_laser_message          laser_messages.h      CARMEN_LASER_MESSAGES_H
 *   carmen_robot_laser_message          robot_messages.h      CARMEN_ROBOT_MESSAGES_H
 *   carmen_base_odometry_message        base_messages.h       CARMEN_BASE_MESSAGES_H
 *   carmen_simulator_truepos_message    simulator_messages.h  SIMULATOR_MESSAGES_H
 * and, for the other converters of readlog.h:
 *   carmen_position_t, carmen_traj_point_t  global.h          CARMEN_GLOBAL_H
 *   carmen_base_velocity_message,
 *   carmen_base_sonar_message,
 *   carmen_base_bumper_message          base_messages.h       CARMEN_BASE_MESSAGES_H
 *   carmen_robot_velocity_message,
 *   carmen_robot_vector_move_message,
 *   carmen_robot_follow_trajectory_message  robot_messages.h  CARMEN_ROBOT_MESSAGES_H
 *   carmen_arm_state_message            arm_messages.h        CARMEN_ARM_MESSAGES_H
 *   carmen_gps_gpgga_message,
 *   carmen_gps_gprmc_message            gps_nmea_messages.h   GPS_NMEA_MESSAGES_H
 *   carmen_imu_message                  imu_messages.h        CARMEN_IMU_MESSAGES_H
 *   carmen_pantilt_scanmark_message,
 *   carmen_pantilt_laserpos_message     pantilt_messages.h    CARMEN_PANTILT_MESSAGES_H
 * (right: the include guard CARMEN's header uses). The layouts are CARMEN's,
 * field for field.
 *
 * Coexisting with CARMEN's headers. These are typedefs of anonymous structs,
 * which C cannot repeat, and CARMEN's headers define them unconditionally.
 * So exactly one side may define each type, and it must be CARMEN's side
 * whenever CARMEN's headers take part, because we cannot stop them:
 *  - CARMEN first (a program includes <carmen/carmen.h>, then ours): each
 *    block below is skipped because CARMEN's guard for it is defined, and
 *    our declarations use CARMEN's types.
 *  - Ours first: if CARMEN's <carmen/carmen.h> can be found (__has_include),
 *    we include it here, before our own definitions, so CARMEN's headers
 *    define the types; a later #include <carmen/carmen.h> in the program is
 *    then a no-op (guard CARMEN_H). carmen.h includes <carmen/map.h>,
 *    <carmen/map_io.h> and <carmen/readlog.h>, which may resolve to ours: our
 *    headers take this step before their own include guard, and skip it
 *    once CARMEN_H is defined, so such a nested include completes with
 *    CARMEN's types already in place.
 *  - Ours alone (no CARMEN on the include path): the blocks below define
 *    the types; no CARMEN header can be included later, since none exists.
 * Define VASCO_CARMEN_STANDALONE to skip the search for carmen.h (then a
 * CARMEN header included *after* ours fails to compile; before is fine).
 * A compiler without __has_include behaves as with VASCO_CARMEN_STANDALONE. */

/* The search comes before this file's own guard: see above. */
#if !defined(CARMEN_H) && !defined(VASCO_CARMEN_STANDALONE) && defined(__has_include)
#if __has_include(<carmen/carmen.h>)
#include <carmen/carmen.h>
#endif
#endif
/* CARMEN's readlog.h includes the headers of the modules whose messages it
 * converts; carmen.h may not include all of them. Where CARMEN is present,
 * so do we (before our own definitions, for the reason above), so that a
 * program that includes one of them after our readlog.h still compiles. */
#if !defined(VASCO_CARMEN_STANDALONE) && defined(__has_include)
#if defined(CARMEN_H) && !defined(VASCO_CARMEN_MODULE_HEADERS_SEARCHED)
#define VASCO_CARMEN_MODULE_HEADERS_SEARCHED
#if __has_include(<carmen/arm_messages.h>)
#include <carmen/arm_messages.h>
#endif
#if __has_include(<carmen/gps_nmea_messages.h>)
#include <carmen/gps_nmea_messages.h>
#endif
#if __has_include(<carmen/imu_messages.h>)
#include <carmen/imu_messages.h>
#endif
#if __has_include(<carmen/pantilt_messages.h>)
#include <carmen/pantilt_messages.h>
#endif
#endif
#endif

#ifndef CARMEN_COMPAT_CARMEN_SHARED_TYPES_H
#define CARMEN_COMPAT_CARMEN_SHARED_TYPES_H

#ifdef __cplusplus
extern "C" {
#endif

/* global.h */
#if !defined(CARMEN_GLOBAL_H) && !defined(VASCO_CARMEN_POINT_T_DEFINED)
#define VASCO_CARMEN_POINT_T_DEFINED
typedef struct {
  double x;
  double y;
  double theta;
} carmen_point_t, *carmen_point_p;
#endif
#if !defined(CARMEN_GLOBAL_H) && !defined(VASCO_CARMEN_GLOBAL_TYPES_DEFINED)
#define VASCO_CARMEN_GLOBAL_TYPES_DEFINED
typedef struct {
  double x;
  double y;
} carmen_position_t, *carmen_position_p;

typedef struct {
  double x;
  double y;
  double theta;
  double t_vel;
  double r_vel;
} carmen_traj_point_t, *carmen_traj_point_p;
#endif

/* laser_messages.h */
#if !defined(CARMEN_LASER_MESSAGES_H) && !defined(VASCO_CARMEN_LASER_TYPES_DEFINED)
#define VASCO_CARMEN_LASER_TYPES_DEFINED
typedef enum {
  SICK_LMS = 0,
  SICK_PLS = 1,
  HOKUYO_URG = 2,
  SIMULATED_LASER = 3,
  SICK_S300 = 4,
  UMKNOWN_PROXIMITY_SENSOR = 99 /* sic: CARMEN's spelling */
} carmen_laser_laser_type_t;

typedef enum {
  REMISSION_NONE = 0,
  REMISSION_DIRECT = 1,
  REMISSION_NORMALIZED = 2
} carmen_laser_remission_type_t;

typedef struct {
  carmen_laser_laser_type_t laser_type;
  double start_angle;        /* angle of the first beam (rad) */
  double fov;                /* field of view (rad) */
  double angular_resolution; /* angle between two beams (rad) */
  double maximum_range;      /* m */
  double accuracy;           /* m */
  carmen_laser_remission_type_t remission_mode;
} carmen_laser_laser_config_t;

/* RAWLASERn */
typedef struct {
  int id;
  carmen_laser_laser_config_t config;
  int num_readings;
  float *range;
  int num_remissions;
  float *remission;
  double timestamp;
  char *host;
} carmen_laser_laser_message;
#endif

/* robot_messages.h */
#if !defined(CARMEN_ROBOT_MESSAGES_H) && !defined(VASCO_CARMEN_ROBOT_LASER_DEFINED)
#define VASCO_CARMEN_ROBOT_LASER_DEFINED
/* ROBOTLASERn, and the old FLASER / RLASER */
typedef struct {
  int id;
  carmen_laser_laser_config_t config;
  int num_readings;
  float *range;
  char *tooclose;
  int num_remissions;
  float *remission;
  carmen_point_t laser_pose;
  carmen_point_t robot_pose;
  double tv, rv;
  double forward_safety_dist, side_safety_dist;
  double turn_axis;
  double timestamp;
  char *host;
} carmen_robot_laser_message;

/* ROBOTVELOCITY */
typedef struct {
  double tv, rv;
  double timestamp;
  char *host;
} carmen_robot_velocity_message;

/* FOLLOWTRAJECTORY */
typedef struct {
  int trajectory_length;
  carmen_traj_point_t *trajectory;
  carmen_traj_point_t robot_position;
  double timestamp;
  char *host;
} carmen_robot_follow_trajectory_message;

/* VECTORMOVE */
typedef struct {
  double distance;
  double theta;
  double timestamp;
  char *host;
} carmen_robot_vector_move_message;
#endif

/* base_messages.h */
#if !defined(CARMEN_BASE_MESSAGES_H) && !defined(VASCO_CARMEN_ODOMETRY_DEFINED)
#define VASCO_CARMEN_ODOMETRY_DEFINED
/* ODOM */
typedef struct {
  double x, y, theta;
  double tv, rv;
  double acceleration;
  double timestamp;
  char *host;
} carmen_base_odometry_message;

/* BASEVELOCITY */
typedef struct {
  double tv, rv;
  double timestamp;
  char *host;
} carmen_base_velocity_message;

/* SONAR */
typedef struct {
  int num_sonars;
  double cone_angle; /* width of a sonar's cone (rad) */
  double *range;
  carmen_point_t *sonar_offsets;
  double timestamp;
  char *host;
} carmen_base_sonar_message;

/* BUMPER */
typedef struct {
  int num_bumpers;
  unsigned char *state;
  carmen_position_t *bumper_offsets;
  double timestamp;
  char *host;
} carmen_base_bumper_message;
#endif

/* simulator_messages.h (CARMEN's guard there has no CARMEN_ prefix) */
#if !defined(SIMULATOR_MESSAGES_H) && !defined(CARMEN_SIMULATOR_MESSAGES_H) && \
    !defined(VASCO_CARMEN_TRUEPOS_DEFINED)
#define VASCO_CARMEN_TRUEPOS_DEFINED
/* TRUEPOS */
typedef struct {
  carmen_point_t truepose;
  carmen_point_t odometrypose;
  double timestamp;
  char *host;
} carmen_simulator_truepos_message;
#endif

/* arm_messages.h */
#if !defined(CARMEN_ARM_MESSAGES_H) && !defined(VASCO_CARMEN_ARM_DEFINED)
#define VASCO_CARMEN_ARM_DEFINED
/* ARM */
typedef struct {
  int flags;
  int num_joints;
  double *joint_angles;
  int num_currents;
  double *joint_currents;
  int num_vels;
  double *joint_angular_vels;
  int gripper_closed;
  double timestamp;
  char *host;
} carmen_arm_state_message;
#endif

/* gps_nmea_messages.h (no CARMEN_ prefix in CARMEN's guard either) */
#if !defined(GPS_NMEA_MESSAGES_H) && !defined(VASCO_CARMEN_GPS_DEFINED)
#define VASCO_CARMEN_GPS_DEFINED
/* NMEAGGA */
typedef struct {
  int nr;              /* number of the GPS unit */
  double utc;
  double latitude;     /* degrees */
  double latitude_dm;  /* DDMM.MMMM, as in the NMEA sentence */
  char lat_orient;     /* 'N' or 'S' */
  double longitude;
  double longitude_dm;
  char long_orient;    /* 'E' or 'W' */
  int gps_quality;
  int num_satellites;
  double hdop;
  double sea_level;
  double altitude;
  double geo_sea_level;
  double geo_sep;
  int data_age;
  double timestamp;
  char *host;
} carmen_gps_gpgga_message;

/* NMEARMC */
typedef struct {
  int nr;
  int validity;        /* 1 valid, 0 not */
  double utc;
  double latitude;
  double latitude_dm;
  char lat_orient;
  double longitude;
  double longitude_dm;
  char long_orient;
  double speed;
  double true_course;
  double variation;
  char var_dir;
  int date;
  double timestamp;
  char *host;
} carmen_gps_gprmc_message;
#endif

/* imu_messages.h */
#if !defined(CARMEN_IMU_MESSAGES_H) && !defined(VASCO_CARMEN_IMU_DEFINED)
#define VASCO_CARMEN_IMU_DEFINED
/* IMU */
typedef struct {
  double accX, accY, accZ;
  double q0, q1, q2, q3; /* orientation quaternion (w, x, y, z) */
  double magX, magY, magZ;
  double gyroX, gyroY, gyroZ;
  double timestamp;
  char *host;
} carmen_imu_message;
#endif

/* pantilt_messages.h */
#if !defined(CARMEN_PANTILT_MESSAGES_H) && !defined(VASCO_CARMEN_PANTILT_DEFINED)
#define VASCO_CARMEN_PANTILT_DEFINED
/* SCANMARK */
typedef struct {
  int type; /* 0 start of a 3D scan, 1 its end */
  int laserid;
  double timestamp;
  char *host;
} carmen_pantilt_scanmark_message;

/* POSITIONLASER */
typedef struct {
  int id;
  double x, y, z;
  double phi, theta, psi;
  double timestamp;
  char *host;
} carmen_pantilt_laserpos_message;
#endif

#ifdef __cplusplus
}
#endif
#endif /* CARMEN_COMPAT_CARMEN_SHARED_TYPES_H */
