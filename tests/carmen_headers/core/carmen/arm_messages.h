/* Stand-in for CARMEN's arm_messages.h (see ../../README.md); CARMEN's carmen.h does not include it: our readlog.h does. */
#ifndef CARMEN_ARM_MESSAGES_H
#define CARMEN_ARM_MESSAGES_H
#define CARMEN_STANDIN_ARM_MESSAGES 1

#ifdef __cplusplus
extern "C" {
#endif

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

#ifdef __cplusplus
}
#endif
#endif
