/* carmen_shared_types.h — the CARMEN 0.7.4 types that our CARMEN headers
 * (readlog.h, map.h) use but CARMEN itself defines in other headers:
 *   carmen_point_t                      global.h              CARMEN_GLOBAL_H
 *   carmen_laser_laser_config_t,
 *   carmen_laser_laser_message          laser_messages.h      CARMEN_LASER_MESSAGES_H
 *   carmen_robot_laser_message          robot_messages.h      CARMEN_ROBOT_MESSAGES_H
 *   carmen_base_odometry_message        base_messages.h       CARMEN_BASE_MESSAGES_H
 *   carmen_simulator_truepos_message    simulator_messages.h  SIMULATOR_MESSAGES_H
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

#ifdef __cplusplus
}
#endif
#endif /* CARMEN_COMPAT_CARMEN_SHARED_TYPES_H */
