/* Stand-in for CARMEN's base_messages.h (see ../../README.md). */
#ifndef CARMEN_BASE_MESSAGES_H
#define CARMEN_BASE_MESSAGES_H
#define CARMEN_STANDIN_BASE_MESSAGES 1

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double x, y, theta;
  double tv, rv;
  double acceleration;
  double timestamp;
  char *host;
} carmen_base_odometry_message;

#define CARMEN_BASE_ODOMETRY_NAME "carmen_base_odometry"

typedef struct {
  double tv, rv;
  double timestamp;
  char *host;
} carmen_base_velocity_message;

typedef struct {
  int num_sonars;
  double cone_angle;
  double *range;
  carmen_point_t *sonar_offsets;
  double timestamp;
  char *host;
} carmen_base_sonar_message;

typedef struct {
  int num_bumpers;
  unsigned char *state;
  carmen_position_t *bumper_offsets;
  double timestamp;
  char *host;
} carmen_base_bumper_message;

#ifdef __cplusplus
}
#endif
#endif
