/* The mapping session from C (vasco_gpu/mapper_c.h), as a C program would use
 * it: inserts one at a time equal one insert of everything (the frame grew
 * with a margin that read and finish do not show), a render with
 * moved poses equals a fresh session fed the moved scans, a fixed frame equals
 * CARMEN's own egrid.h call by call, and each error gives its code and a
 * message chosen by the error's kind, and one handle survives two threads.
 * Exit 0 when every check passes. */
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "carmen/egrid.h"
#include "vasco_gpu/mapper_c.h"

#define NUM_SCANS 60
#define NUM_BEAMS 181

static int failures = 0;
#define CHECK(cond, ...)                                       \
  do {                                                         \
    if (!(cond)) {                                             \
      fprintf(stderr, "%s:%d: check failed: ", __FILE__, __LINE__); \
      fprintf(stderr, __VA_ARGS__);                            \
      fprintf(stderr, "\n");                                   \
      ++failures;                                              \
    }                                                          \
  } while (0)

static double poses[NUM_SCANS * 3];
static int counts[NUM_SCANS];
static float ranges[NUM_SCANS * NUM_BEAMS];
static double firsts[NUM_SCANS], steps[NUM_SCANS];

/* A robot driving down a 4 m wide corridor with a few odd readings. */
static void make_scans(void) {
  for (int s = 0; s < NUM_SCANS; ++s) {
    poses[3 * s] = 0.1 * s;
    poses[3 * s + 1] = 0.02 * sin(0.3 * s);
    poses[3 * s + 2] = 0.01 * s;
    counts[s] = NUM_BEAMS;
    firsts[s] = -M_PI / 2;
    steps[s] = M_PI / 180;
    for (int b = 0; b < NUM_BEAMS; ++b) {
      const double a = -M_PI / 2 + b * M_PI / 180;
      double r = fabs(sin(a)) > 1e-3 ? 2.0 / fabs(sin(a)) : 60.0;
      if (r > 60.0) r = 60.0;
      if ((s * 7 + b) % 97 == 0) r = -INFINITY;
      if ((s * 5 + b) % 89 == 0) r = NAN;
      ranges[s * NUM_BEAMS + b] = (float)r;
    }
  }
}

static float *read_all(vasco_mapper *m, int *sx, int *sy) {
  CHECK(vasco_mapper_grid_size(m, sx, sy) == VASCO_OK, "grid size");
  float *cells = malloc((size_t)*sx * (size_t)*sy * sizeof(float));
  CHECK(vasco_mapper_read(m, 0, 0, *sx, *sy, cells) == VASCO_OK, "read: %s", vasco_last_error(m));
  return cells;
}

static void expect_same_grid(vasco_mapper *a, vasco_mapper *b, const char *what) {
  int ax, ay, bx, by;
  float *ca = read_all(a, &ax, &ay), *cb = read_all(b, &bx, &by);
  CHECK(ax == bx && ay == by, "%s: sizes %dx%d vs %dx%d", what, ax, ay, bx, by);
  if (ax == bx && ay == by)
    CHECK(memcmp(ca, cb, (size_t)ax * ay * sizeof(float)) == 0, "%s: the grids differ", what);
  free(ca);
  free(cb);
}

static vasco_mapper *create(const vasco_mapper_params *p) {
  vasco_mapper *m = NULL;
  const vasco_status st = vasco_mapper_create(p, "cpu_double", &m);
  CHECK(st == VASCO_OK && m != NULL, "create: %s", vasco_last_error(NULL));
  return m;
}

static void incremental_and_render(const vasco_mapper_params *p) {
  vasco_mapper *one_by_one = create(p), *at_once = create(p);
  for (int s = 0; s < NUM_SCANS; ++s)
    CHECK(vasco_mapper_insert(one_by_one, 1, poses + 3 * s, counts + s, ranges + s * NUM_BEAMS, firsts + s,
                              steps + s) == VASCO_OK, "insert %d: %s", s, vasco_last_error(one_by_one));
  CHECK(vasco_mapper_insert(at_once, NUM_SCANS, poses, counts, ranges, firsts, steps) == VASCO_OK, "insert");
  CHECK(vasco_mapper_num_scans(one_by_one) == NUM_SCANS, "scan count");
  /* The grid grew with a margin; the frame read shows is the PROTOCOL frame. */
  int gx, gy;
  CHECK(vasco_mapper_grid_size(one_by_one, &gx, &gy) == VASCO_OK, "grid size");
  vasco_mapper *in_its_frame = NULL;
  CHECK(vasco_mapper_create_fixed(p, "cpu_double", gx, gy, poses[2], &in_its_frame) == VASCO_OK, "create_fixed");
  CHECK(vasco_mapper_insert(in_its_frame, NUM_SCANS, poses, counts, ranges, firsts, steps) == VASCO_OK, "insert");
  expect_same_grid(one_by_one, in_its_frame, "one by one vs a fixed frame of its size");
  expect_same_grid(one_by_one, at_once, "one by one vs at once");
  vasco_mapper_destroy(in_its_frame);
  /* Rendered again with its own poses: the PROTOCOL frame, as one insert of everything. */
  CHECK(vasco_mapper_render(one_by_one, NUM_SCANS, poses) == VASCO_OK, "render: %s", vasco_last_error(one_by_one));
  expect_same_grid(one_by_one, at_once, "one by one, rendered again, vs at once");

  /* A loop closure: every pose moved. */
  double moved[NUM_SCANS * 3];
  for (int s = 0; s < NUM_SCANS; ++s) {
    moved[3 * s] = poses[3 * s] + 0.5 + 0.001 * s;
    moved[3 * s + 1] = poses[3 * s + 1] - 0.25;
    moved[3 * s + 2] = poses[3 * s + 2] + 0.02;
  }
  CHECK(vasco_mapper_render(one_by_one, NUM_SCANS, moved) == VASCO_OK, "render: %s", vasco_last_error(one_by_one));
  vasco_mapper *fresh = create(p);
  CHECK(vasco_mapper_insert(fresh, NUM_SCANS, moved, counts, ranges, firsts, steps) == VASCO_OK, "insert moved");
  expect_same_grid(one_by_one, fresh, "render vs fresh");

  vasco_map map;
  CHECK(vasco_mapper_finish(one_by_one, 4, 20, &map) == VASCO_OK, "finish: %s", vasco_last_error(one_by_one));
  CHECK(map.size_x > 0 && map.size_y > 0 && map.cells != NULL, "finished map is empty");
  CHECK(fabs(map.resolution - 4 * p->resolution) < 1e-12, "finished resolution %g", map.resolution);
  vasco_mapper_destroy(one_by_one);
  vasco_mapper_destroy(at_once);
  vasco_mapper_destroy(fresh);
}

static void fixed_frame_equals_egrid(const vasco_mapper_params *p) {
  const int sx = 500, sy = 400;
  vasco_mapper *m = NULL;
  CHECK(vasco_mapper_create_fixed(p, "cpu_threads", sx, sy, 0.25, &m) == VASCO_OK, "create_fixed: %s",
        vasco_last_error(NULL));
  evidence_grid g;
  carmen_mapper_initialize_evidence_grid(&g, sx, sy, p->resolution, 0.25, p->p_prior, p->p_occ, p->p_emp, 0.99,
                                         p->range_sure, p->range_max, p->wall_size);
  for (int s = 0; s < NUM_SCANS; ++s) {
    vasco_mapper_insert(m, 1, poses + 3 * s, counts + s, ranges + s * NUM_BEAMS, firsts + s, steps + s);
    carmen_mapper_update_evidence_grid(&g, poses[3 * s], poses[3 * s + 1], poses[3 * s + 2], NUM_BEAMS,
                                       ranges + s * NUM_BEAMS, steps[s], firsts[s]);
  }
  int gx, gy;
  float *cells = read_all(m, &gx, &gy);
  CHECK(gx == sx && gy == sy, "fixed frame size %dx%d", gx, gy);
  int differ = 0;
  for (int x = 0; x < sx && gx == sx; ++x)
    for (int y = 0; y < sy && gy == sy; ++y)
      differ += memcmp(&cells[(size_t)x * sy + y], &g.prob[x][y], sizeof(float)) != 0;
  CHECK(differ == 0, "fixed frame: %d cells differ from CARMEN's egrid", differ);
  free(cells);
  carmen_mapper_free_evidence_grid(&g);
  vasco_mapper_destroy(m);
}

static void errors(const vasco_mapper_params *p) {
  vasco_mapper *m = NULL;
  CHECK(vasco_mapper_create(p, "gpu9000", &m) == VASCO_ERR_BACKEND && m == NULL, "unknown backend");
  CHECK(strstr(vasco_last_error(NULL), "gpu9000") != NULL, "message: %s", vasco_last_error(NULL));
  vasco_mapper_params bad = *p;
  bad.p_occ = 1.5;
  CHECK(vasco_mapper_create(&bad, NULL, &m) == VASCO_ERR_INVALID_ARGUMENT, "p_occ 1.5");
  CHECK(strstr(vasco_last_error(NULL), "vasco_p_occ") != NULL, "message: %s", vasco_last_error(NULL));
  m = create(p);
  vasco_map map;
  CHECK(vasco_mapper_finish(m, 1, 0, &map) == VASCO_ERR_STATE, "finish before insert");
  CHECK(vasco_mapper_insert(m, NUM_SCANS, poses, counts, ranges, firsts, steps) == VASCO_OK, "insert");
  float out[4];
  CHECK(vasco_mapper_read(m, -1, 0, 2, 2, out) == VASCO_ERR_INVALID_ARGUMENT, "window outside");
  CHECK(strstr(vasco_last_error(m), "window") != NULL, "message: %s", vasco_last_error(m));
  CHECK(vasco_mapper_render(m, 3, poses) == VASCO_ERR_INVALID_ARGUMENT, "render with too few poses");
  double far[3] = {1e8, 0, 0};
  CHECK(vasco_mapper_insert(m, 1, far, counts, ranges, firsts, steps) == VASCO_ERR_TOO_LARGE, "far scan");
  CHECK(vasco_mapper_num_scans(m) == NUM_SCANS, "a failed insert stored a scan");
  CHECK(vasco_mapper_insert(m, 1, NULL, counts, ranges, firsts, steps) == VASCO_ERR_INVALID_ARGUMENT, "NULL");
  double bad_pose[3] = {0, NAN, 0};
  CHECK(vasco_mapper_insert(m, 1, bad_pose, counts, ranges, firsts, steps) == VASCO_ERR_INVALID_ARGUMENT, "NaN pose");
  CHECK(strstr(vasco_last_error(m), "scan 0") != NULL, "message: %s", vasco_last_error(m));
  double nan_first[1] = {NAN}, inf_step[1] = {INFINITY}, pose0[3] = {0, 0, 0};
  CHECK(vasco_mapper_insert(m, 1, pose0, counts, ranges, nan_first, steps) == VASCO_ERR_INVALID_ARGUMENT,
        "NaN first angle");
  CHECK(strstr(vasco_last_error(m), "angle") != NULL, "message: %s", vasco_last_error(m));
  CHECK(vasco_mapper_insert(m, 1, pose0, counts, ranges, firsts, inf_step) == VASCO_ERR_INVALID_ARGUMENT,
        "inf angle step");
  double moved[NUM_SCANS * 3];
  memcpy(moved, poses, sizeof moved);
  moved[3 * 7 + 2] = INFINITY;
  CHECK(vasco_mapper_render(m, NUM_SCANS, moved) == VASCO_ERR_INVALID_ARGUMENT, "inf heading");
  CHECK(strstr(vasco_last_error(m), "pose 7") != NULL, "message: %s", vasco_last_error(m));
  CHECK(vasco_mapper_read(m, 0, 0, 0, 5, NULL) == VASCO_OK, "a 0-wide window: %s", vasco_last_error(m));
  CHECK(vasco_mapper_read(m, 3, 3, 5, 0, out) == VASCO_OK, "a 0-high window: %s", vasco_last_error(m));
  CHECK(vasco_mapper_finish(m, 4, INT_MAX, &map) == VASCO_OK, "border INT_MAX: %s", vasco_last_error(m));
  CHECK(vasco_mapper_num_scans(m) == NUM_SCANS, "the failed calls stored a scan");
  vasco_mapper_destroy(m);
}

/* The memory budget: over it is VASCO_ERR_OUT_OF_MEMORY (not INTERNAL), and
 * a budget the session already exceeds is refused, keeping the old one. */
static void memory_budget(const vasco_mapper_params *p) {
  vasco_mapper *m = create(p);
  CHECK(vasco_mapper_insert(m, NUM_SCANS, poses, counts, ranges, firsts, steps) == VASCO_OK, "insert");
  CHECK(vasco_mapper_set_max_memory(m, 1024) == VASCO_ERR_OUT_OF_MEMORY, "a budget below the session's need");
  CHECK(vasco_mapper_set_max_memory(m, 64ull << 20) == VASCO_OK, "64 MiB: %s", vasco_last_error(m));
  double far[3] = {2000, 0, 0}; /* 2 km out: a grid of about 500 MiB */
  CHECK(vasco_mapper_insert(m, 1, far, counts, ranges, firsts, steps) == VASCO_ERR_OUT_OF_MEMORY, "over budget");
  CHECK(strstr(vasco_last_error(m), "budget") != NULL, "message: %s", vasco_last_error(m));
  CHECK(vasco_mapper_num_scans(m) == NUM_SCANS, "a refused insert stored a scan");
  CHECK(vasco_mapper_set_max_memory(m, 0) == VASCO_OK, "no budget");
  CHECK(vasco_mapper_insert(m, 1, far, counts, ranges, firsts, steps) == VASCO_OK, "no budget: %s", vasco_last_error(m));
  CHECK(vasco_mapper_set_max_memory(NULL, 0) == VASCO_ERR_INVALID_ARGUMENT, "NULL handle");
  vasco_mapper_destroy(m);
}

/* Two threads on one handle: inserts, reads, finishes and counts interleave
 * under the handle's lock (run under ASan/TSan: no use after free). */
enum { ROUNDS = 30 };
static void *hammer(void *arg) {
  vasco_mapper *m = arg;
  float out[16];
  vasco_map map;
  int sx, sy;
  for (int i = 0; i < ROUNDS; ++i) {
    const int s = i % NUM_SCANS;
    CHECK(vasco_mapper_insert(m, 1, poses + 3 * s, counts + s, ranges + s * NUM_BEAMS, firsts + s, steps + s) ==
              VASCO_OK, "threaded insert: %s", vasco_last_error(m));
    CHECK(vasco_mapper_grid_size(m, &sx, &sy) == VASCO_OK, "threaded size");
    CHECK(vasco_mapper_read(m, sx / 2, sy / 2, 4, 4, out) == VASCO_OK, "threaded read");
    CHECK(vasco_mapper_finish(m, 2, 5, &map) == VASCO_OK, "threaded finish");
    (void)vasco_mapper_num_scans(m);
  }
  return NULL;
}

static void two_threads_one_handle(const vasco_mapper_params *p) {
  vasco_mapper *m = create(p);
  pthread_t a, b;
  CHECK(pthread_create(&a, NULL, hammer, m) == 0, "thread a");
  CHECK(pthread_create(&b, NULL, hammer, m) == 0, "thread b");
  pthread_join(a, NULL);
  pthread_join(b, NULL);
  CHECK(vasco_mapper_num_scans(m) == 2 * ROUNDS, "%zu scans after two threads", vasco_mapper_num_scans(m));
  vasco_mapper_destroy(m);
}

int main(void) {
  make_scans();
  vasco_mapper_params p;
  vasco_mapper_params_default(&p);
  CHECK(p.resolution == 0.025 && p.downsample == 4, "defaults");
  incremental_and_render(&p);
  fixed_frame_equals_egrid(&p);
  errors(&p);
  memory_budget(&p);
  two_threads_one_handle(&p);
  if (failures) {
    fprintf(stderr, "mapper_c_api_test: %d checks failed\n", failures);
    return 1;
  }
  printf("mapper_c_api_test: every check passed\n");
  return 0;
}
