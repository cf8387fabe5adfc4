/* Stand-in for CARMEN's laser_messages.h (laser-new; see ../../README.md). */
#ifndef CARMEN_LASER_MESSAGES_H
#define CARMEN_LASER_MESSAGES_H
#define CARMEN_STANDIN_LASER_MESSAGES 1

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  SICK_LMS = 0,
  SICK_PLS = 1,
  HOKUYO_URG = 2,
  SIMULATED_LASER = 3,
  SICK_S300 = 4,
  UMKNOWN_PROXIMITY_SENSOR = 99
} carmen_laser_laser_type_t;

typedef enum { REMISSION_NONE = 0, REMISSION_DIRECT = 1, REMISSION_NORMALIZED = 2 } carmen_laser_remission_type_t;

typedef struct {
  carmen_laser_laser_type_t laser_type;
  double start_angle;
  double fov;
  double angular_resolution;
  double maximum_range;
  double accuracy;
  carmen_laser_remission_type_t remission_mode;
} carmen_laser_laser_config_t;

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

#define CARMEN_LASER_LASER1_NAME "carmen_laser_laser1"

typedef struct {
  int frontlaser_stalled;
  int rearlaser_stalled;
  int laser3_stalled;
  int laser4_stalled;
} carmen_laser_alive_message;

#ifdef __cplusplus
}
#endif
#endif
