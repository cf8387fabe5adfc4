/* A stand-in for CARMEN's clf-get-oldlaser, written for the install test (no
 * CARMEN code): it turns each ROBOTLASER1 line of a log into an old-style
 * FLASER line, copying the message's host with strncpy as that program does,
 * without checking the converter's return value. A converter that fails on a
 * bad line must leave the message usable (a valid host string, counts that
 * match the arrays), or exit as CARMEN's does; it must never crash it.
 *
 *   oldlaser_standin LOG */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <carmen/carmen_stdio.h>
#include <carmen/readlog.h>

#define LINE_MAX_BYTES 100000

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: oldlaser_standin LOG\n");
    return 2;
  }
  carmen_FILE *fp = carmen_fopen(argv[1], "r");
  if (fp == NULL) return 1;
  carmen_logfile_index_p index = carmen_logfile_index_messages(fp);
  if (index == NULL) return 1;
  char *line = malloc(LINE_MAX_BYTES);
  static carmen_robot_laser_message laser; /* zeroed once, then reused: as CARMEN's tools keep it */
  char host[64];
  for (int i = 0; i < index->num_messages; ++i) {
    if (carmen_logfile_read_line(index, fp, i, LINE_MAX_BYTES, line) < 0) continue;
    if (strncmp(line, "ROBOTLASER1 ", 12) != 0) continue;
    carmen_string_to_robot_laser_message(line, &laser);
    strncpy(host, laser.host, sizeof host - 1);
    host[sizeof host - 1] = '\0';
    printf("FLASER %d", laser.num_readings);
    for (int j = 0; j < laser.num_readings; ++j) printf(" %.2f", laser.range[j]);
    printf(" %.6f %.6f %.6f %.6f %.6f %.6f %.6f %s %.6f\n", laser.laser_pose.x, laser.laser_pose.y,
           laser.laser_pose.theta, laser.robot_pose.x, laser.robot_pose.y, laser.robot_pose.theta, laser.timestamp,
           host, laser.timestamp);
  }
  free(line);
  carmen_logfile_free_index(&index);
  carmen_fclose(fp);
  return 0;
}
