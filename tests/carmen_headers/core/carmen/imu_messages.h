/* Stand-in for CARMEN's imu_messages.h (see ../../README.md); not included by carmen.h. */
#ifndef CARMEN_IMU_MESSAGES_H
#define CARMEN_IMU_MESSAGES_H
#define CARMEN_STANDIN_IMU_MESSAGES 1

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double accX, accY, accZ;
  double q0, q1, q2, q3;
  double magX, magY, magZ;
  double gyroX, gyroY, gyroZ;
  double timestamp;
  char *host;
} carmen_imu_message;

#ifdef __cplusplus
}
#endif
#endif
