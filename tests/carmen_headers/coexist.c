/* Header coexistence: a CARMEN program that includes CARMEN's headers (the
 * stand-ins in core/ and maptools/) and ours, in the order OURS_FIRST says.
 * CMake builds it several ways (include order x include-path order); each
 * build must compile (no type defined twice), see CARMEN's layouts
 * (layout_check.h), and work at run time.
 *   coexist FREIBURG_MAP */
/* A user's program: it does not opt out of the search for CARMEN's carmen.h
 * as every target of this tree does. */
#undef VASCO_CARMEN_STANDALONE
#ifdef OURS_FIRST
#include <carmen/egrid.h>
#include <carmen/readlog.h>
#include <carmen/map_io.h>
#include <carmen/map.h>
#include <carmen/carmen_stdio.h>
#ifdef WITH_CARMEN
#include <carmen/carmen.h>
#endif
#else
#include <carmen/carmen.h>
#include <carmen/carmen_stdio.h>
#include <carmen/map.h>
#include <carmen/map_io.h>
#include <carmen/readlog.h>
#include <carmen/egrid.h>
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "layout_check.h"

/* The build says which side must have defined the shared types. */
#if defined(WITH_CARMEN) && !(defined(CARMEN_STANDIN_GLOBAL) && defined(CARMEN_STANDIN_ROBOT_MESSAGES) && \
                              defined(CARMEN_STANDIN_SIMULATOR_MESSAGES) && defined(CARMEN_STANDIN_BASE_MESSAGES))
#error "CARMEN's headers did not define the shared message types"
#endif
/* The module headers CARMEN's carmen.h leaves out: our readlog.h includes
 * CARMEN's, so that CARMEN's types are the ones defined. */
#if defined(WITH_CARMEN) && !(defined(CARMEN_STANDIN_ARM_MESSAGES) && defined(CARMEN_STANDIN_GPS_NMEA_MESSAGES) && \
                              defined(CARMEN_STANDIN_IMU_MESSAGES) && defined(CARMEN_STANDIN_PANTILT_MESSAGES))
#error "CARMEN's module headers did not define the other message types"
#endif
/* A program may include them again, in any order. */
#ifdef WITH_CARMEN
#include <carmen/imu_messages.h>
#include <carmen/arm_messages.h>
#include <carmen/pantilt_messages.h>
#include <carmen/gps_nmea_messages.h>
#endif
#if defined(EXPECT_CARMEN_MAP) != defined(CARMEN_STANDIN_MAP)
#error "the wrong map.h was used"
#endif
#if !defined(WITH_CARMEN) && defined(CARMEN_STANDIN_CARMEN)
#error "a CARMEN header was found in the standalone build"
#endif
#if !defined(EGRID_H) || !defined(CARMEN_MAP_IO_H) || !defined(CARMEN_READLOG_H) || !defined(DGC_MY_STDIO_H)
#error "CARMEN's guard names are missing"
#endif

static int fail(const char *what) {
  fprintf(stderr, "coexist: %s\n", what);
  return 1;
}

/* A FLASER line through readlog, with CARMEN's struct. */
static int check_flaser(void) {
  char line[] = "FLASER 3 1.0 2.0 3.0 0.5 0.25 0.125 7.0 8.0 9.0 1.5 host 2.5\n";
  carmen_robot_laser_message m;
  memset(&m, 0, sizeof m);
  if (carmen_string_to_robot_laser_message_orig(line, &m) == NULL) return fail("FLASER not parsed");
  const int ok = m.num_readings == 3 && m.range[2] == 3.0f && m.laser_pose.theta == 0.125 &&
                 m.robot_pose.x == 7.0 && m.timestamp == 1.5 && strcmp(m.host, "host") == 0;
  free(m.range);
  free(m.tooclose);
  free(m.remission);
  free(m.host);
  return ok ? 0 : fail("FLASER fields wrong");
}

/* The other converters, with CARMEN's structs; and a bad line leaves a
 * message CARMEN's callers can use. */
static int check_others(void) {
  char imu_line[] = "IMU 0.1 0.2 9.8 1 0 0 0 0.3 0.4 0.5 0.01 0.02 0.03 7.5 host 1.25\n";
  char sonar_line[] = "SONAR 0.5 2 1.25 2.5 0.1 0.2 0.3 -0.1 -0.2 -0.3 7.5 host 1.25\n";
  char bad_line[] = "SONAR 0.5 2000000000 1\n";
  carmen_imu_message imu;
  carmen_base_sonar_message sonar;
  memset(&imu, 0, sizeof imu);
  memset(&sonar, 0, sizeof sonar);
  char *rest = carmen_string_to_imu_message(imu_line, &imu);
  int ok = rest != NULL && atof(rest) == 1.25 && imu.accZ == 9.8 && imu.gyroZ == 0.03 && strcmp(imu.host, "host") == 0;
  rest = carmen_string_to_base_sonar_message(sonar_line, &sonar);
  ok = ok && rest != NULL && sonar.num_sonars == 2 && sonar.sonar_offsets[1].theta == -0.3;
  rest = carmen_string_to_base_sonar_message(bad_line, &sonar);
  ok = ok && rest != NULL && atof(rest) == 0.0 && sonar.num_sonars == 0 && sonar.range == NULL && sonar.host != NULL &&
       sonar.host[0] == '\0' && carmen_readlog_last_error()[0] != '\0';
  free(imu.host);
  free(sonar.range);
  free(sonar.sonar_offsets);
  free(sonar.host);
  return ok ? 0 : fail("other converters wrong");
}

static int check_map(char *file) {
  carmen_map_config_t config;
  if (carmen_map_read_gridmap_config(file, &config) != 0) return fail("map config not read");
  const int ok = config.x_size == 300 && config.y_size == 300 && strcmp(config.map_name, file) == 0;
  free(config.map_name);
  carmen_world_point_t wp;
  wp.pose.theta = 1.0;
  wp.map = NULL;
  return ok && wp.pose.theta == 1.0 ? 0 : fail("map config wrong");
}

static int check_egrid(void) {
  evidence_grid g;
  if (carmen_mapper_initialize_evidence_grid(&g, 4, 4, 0.5, 0, 0.5, 0.55, 0.45, 0.95, 1, 2, 0.2) != 0)
    return fail("egrid init");
  const int ok = g.prob[3][3] == -1.0f;
  carmen_mapper_free_evidence_grid(&g);
  return ok ? 0 : fail("egrid cell");
}

int main(int argc, char **argv) {
  if (argc != 2) return fail("usage: coexist FREIBURG_MAP");
  return check_flaser() || check_others() || check_map(argv[1]) || check_egrid();
}
