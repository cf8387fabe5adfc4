/* Stand-in for CARMEN's robot_messages.h (see ../../README.md). Like
 * CARMEN's, it needs global.h and laser_messages.h first. */
#ifndef CARMEN_ROBOT_MESSAGES_H
#define CARMEN_ROBOT_MESSAGES_H
#define CARMEN_STANDIN_ROBOT_MESSAGES 1

#ifdef __cplusplus
extern "C" {
#endif

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

#define CARMEN_ROBOT_FRONTLASER_NAME "carmen_robot_frontlaser"

typedef struct {
  double tv, rv;
  double timestamp;
  char *host;
} carmen_robot_velocity_message;

typedef struct {
  int trajectory_length;
  carmen_traj_point_t *trajectory;
  carmen_traj_point_t robot_position;
  double timestamp;
  char *host;
} carmen_robot_follow_trajectory_message;

typedef struct {
  double distance;
  double theta;
  double timestamp;
  char *host;
} carmen_robot_vector_move_message;

#ifdef __cplusplus
}
#endif
#endif
