/* Stand-in for CARMEN's global.h (see ../../README.md). */
#ifndef CARMEN_GLOBAL_H
#define CARMEN_GLOBAL_H
#define CARMEN_STANDIN_GLOBAL 1

#ifdef __cplusplus
extern "C" {
#endif

#define CARMEN_MAJOR_VERSION 0
#define CARMEN_MINOR_VERSION 7
#define CARMEN_REVISION 4

typedef struct {
  double x;
  double y;
  double theta;
} carmen_point_t, *carmen_point_p;

typedef struct {
  double x;
  double y;
  double theta;
  double t_vel;
  double r_vel;
} carmen_traj_point_t, *carmen_traj_point_p;

typedef struct {
  double x;
  double y;
} carmen_position_t, *carmen_position_p;

int carmen_file_exists(char *filename);

#ifdef __cplusplus
}
#endif
#endif
