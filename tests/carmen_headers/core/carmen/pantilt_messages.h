/* Stand-in for CARMEN's pantilt_messages.h (see ../../README.md); not included by carmen.h. */
#ifndef CARMEN_PANTILT_MESSAGES_H
#define CARMEN_PANTILT_MESSAGES_H
#define CARMEN_STANDIN_PANTILT_MESSAGES 1

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  int type;
  int laserid;
  double timestamp;
  char *host;
} carmen_pantilt_scanmark_message;

typedef struct {
  int id;
  double x, y, z;
  double phi, theta, psi;
  double timestamp;
  char *host;
} carmen_pantilt_laserpos_message;

#ifdef __cplusplus
}
#endif
#endif
