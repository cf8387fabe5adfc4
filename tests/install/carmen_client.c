/* A CARMEN client as CARMEN's own log tools are written (readlog, egrid,
 * map_io), built against the *installed* vasco_gpu: it maps a log by the
 * golden PROTOCOL with vasco's default parameters (downsample 4, border 20)
 * and writes a CARMEN map. The install test compares that map with CARMEN's
 * golden map of the same log.
 *
 *   carmen_client LOG OUT.map */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <carmen/carmen_stdio.h>
#include <carmen/egrid.h>
#include <carmen/map_io.h>
#include <carmen/readlog.h>

#define LINE_MAX_BYTES (1 << 20)

typedef struct {
  double x, y, theta, start, step;
  int n;
  float *range;
} scan_t;

static int read_scans(const char *path, scan_t **out) {
  carmen_FILE *fp = carmen_fopen(path, "r");
  if (fp == NULL) return -1;
  carmen_logfile_index_p index = carmen_logfile_index_messages(fp);
  if (index == NULL) return -1;
  char *line = malloc(LINE_MAX_BYTES);
  int count = 0, cap = 0;
  scan_t *scans = NULL;
  while (!carmen_logfile_eof(index)) {
    if (carmen_logfile_read_next_line(index, fp, LINE_MAX_BYTES, line) < 0) continue;
    carmen_robot_laser_message m;
    memset(&m, 0, sizeof m);
    char *ok = NULL;
    if (strncmp(line, "FLASER ", 7) == 0) ok = carmen_string_to_robot_laser_message_orig(line, &m);
    else if (strncmp(line, "ROBOTLASER1 ", 12) == 0) ok = carmen_string_to_robot_laser_message(line, &m);
    else continue;
    if (ok == NULL) return -1;
    if (count == cap) {
      cap = cap ? 2 * cap : 1024;
      scans = realloc(scans, sizeof(scan_t) * (size_t)cap);
    }
    scan_t *s = &scans[count++];
    s->x = m.laser_pose.x;
    s->y = m.laser_pose.y;
    s->theta = m.laser_pose.theta;
    s->start = m.config.start_angle;
    s->step = m.config.angular_resolution;
    s->n = m.num_readings;
    s->range = m.range; /* kept: the next message gets a fresh one */
    free(m.tooclose);
    free(m.remission);
    free(m.host);
  }
  free(line);
  carmen_logfile_free_index(&index);
  carmen_fclose(fp);
  *out = scans;
  return count;
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: carmen_client LOG OUT.map\n");
    return 2;
  }
  const double res = 0.025, range_max = 10.0;
  scan_t *scans = NULL;
  const int n = read_scans(argv[1], &scans);
  if (n <= 0) {
    fprintf(stderr, "carmen_client: %s: no scans (%s)\n", argv[1], carmen_readlog_last_error());
    return 1;
  }
  /* The golden PROTOCOL's grid: centred on the first scan. */
  double mx = 0, my = 0;
  for (int i = 0; i < n; ++i) {
    if (fabs(scans[i].x - scans[0].x) > mx) mx = fabs(scans[i].x - scans[0].x);
    if (fabs(scans[i].y - scans[0].y) > my) my = fabs(scans[i].y - scans[0].y);
  }
  mx += range_max + res;
  my += range_max + res;
  const int sx = 2 * (int)ceil(mx / res) + 2, sy = 2 * (int)ceil(my / res) + 2;
  evidence_grid g;
  if (carmen_mapper_initialize_evidence_grid(&g, sx, sy, res, scans[0].theta, 0.5, 0.55, 0.45, 0.99, 5.0,
                                             range_max, 0.2) != 0)
    return 1;
  for (int i = 0; i < n; ++i)
    carmen_mapper_update_evidence_grid(&g, scans[i].x, scans[i].y, scans[i].theta, scans[i].n, scans[i].range,
                                       scans[i].step, scans[i].start);
  carmen_mapper_finish_evidence_grid(&g, 4, 20);
  carmen_FILE *out = carmen_fopen(argv[2], "w");
  if (out == NULL) return 1;
  const int rc = carmen_map_write_all(out, g.prob, g.size_x, g.size_y, g.resolution, argv[1], "carmen_client",
                                      argv[1], "carmen_client", NULL, 0, NULL, 0, NULL, 0);
  carmen_fclose(out);
  carmen_mapper_free_evidence_grid(&g);
  for (int i = 0; i < n; ++i) free(scans[i].range);
  free(scans);
  return rc == 0 ? 0 : 1;
}
