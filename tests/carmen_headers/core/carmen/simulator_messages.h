/* Stand-in for CARMEN's simulator_messages.h (see ../../README.md); CARMEN's
 * guard here has no CARMEN_ prefix. */
#ifndef SIMULATOR_MESSAGES_H
#define SIMULATOR_MESSAGES_H
#define CARMEN_STANDIN_SIMULATOR_MESSAGES 1

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  carmen_point_t truepose;
  carmen_point_t odometrypose;
  double timestamp;
  char *host;
} carmen_simulator_truepos_message;

#define CARMEN_SIMULATOR_TRUEPOS_NAME "carmen_simulator_truepos"

#ifdef __cplusplus
}
#endif
#endif
