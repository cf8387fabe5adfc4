/* egrid.h — CARMEN 0.7.4's evidence-grid API (vasco's libegrid), offered
 * unchanged: code written against vasco/egrid.h compiles and links against
 * vasco_gpu instead. The implementation is vasco_gpu's double-precision
 * oracle, which reproduces CARMEN's arithmetic bit for bit.
 *
 * Differences from CARMEN, all on input CARMEN would crash on:
 *  - allocation failure prints a message, returns -1 (as CARMEN does) and
 *    leaves `prob` NULL, so every later call is a no-op;
 *  - NULL pointers and negative sizes are rejected with a message (and -1). */
#ifndef EGRID_H
#define EGRID_H /* CARMEN's guard name: a program may test it */

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double resolution;
  int size_x, size_y;
  double theta_offset;
  double prior_occ, occ_evidence, emp_evidence, max_prob; /* max_prob is stored, never used */
  double max_sure_range, max_range, wall_thickness;
  float **prob; /* prob[x][y]; -1 = unknown */
  int distance_table_size;
  double **distance_table; /* distance_table[i][j] = sqrt(i*i + j*j) * resolution */
  int first;               /* 1 until the first update */
  double start_x, start_y, start_theta;
} evidence_grid;

/* 0, or -1 when the grid cannot be allocated (or the arguments are bad). */
int carmen_mapper_initialize_evidence_grid(evidence_grid *grid, int size_x, int size_y,
                                            double resolution, double theta_offset,
                                            double prior_occ, double occ_evidence,
                                            double emp_evidence, double max_prob,
                                            double max_sure_range, double max_range,
                                            double wall_thickness);

/* Beam i points at laser_theta + first_beam_angle + i * angular_resolution
 * (accumulated by repeated addition, as CARMEN does). */
void carmen_mapper_update_evidence_grid(evidence_grid *grid, double laser_x, double laser_y,
                                        double laser_theta, int num_readings, float *laser_range,
                                        double angular_resolution, double first_beam_angle);

/* Beam i points at laser_theta + laser_angle[i]; angular_resolution and
 * first_beam_angle are taken, and unused, as in CARMEN. */
void carmen_mapper_update_evidence_grid_general(evidence_grid *grid, double laser_x,
                                                double laser_y, double laser_theta,
                                                int num_readings, float *laser_range,
                                                float *laser_angle, double angular_resolution,
                                                double first_beam_angle);

/* Every cell to the prior. */
void carmen_mapper_clear_evidence_grid(evidence_grid *grid);

/* Downsamples by `downsample` and crops to the known cells plus `border`
 * (DESIGN §2 step 7); size and resolution are updated in place. A grid that
 * mapped nothing (no cell known) and is more than 4 * border + 1 blocks wide
 * or high is where CARMEN's finish dies "Out of memory" (its map size comes
 * out negative): this one stops the process there too (exit status 1, a
 * message saying why), so that no half-written map file follows;
 * vasco_egrid_finish_would_stop says so beforehand. */
void carmen_mapper_finish_evidence_grid(evidence_grid *grid, int downsample, int border);

void carmen_mapper_free_evidence_grid(evidence_grid *grid);

/* vasco_gpu extension: the backend that grids initialised from now on run on
 * ("cpu_double", the default; "cpu_threads"; "cpu_float"; "cuda" or
 * "cuda_float" (float mode); "cuda_exact"; "auto": the names of the backend
 * registry, vasco_gpu/backend.h). Every name vasco_egrid_grid_backend
 * returns is accepted here. Without a call (or after one with ""), the
 * environment variable VASCO_GPU_BACKEND chooses. Returns 0, or -1 for an
 * unknown name.
 *
 * How g->prob stays what CARMEN holds: every update runs on the backend's
 * mapping session and then copies back into g->prob the square of cells the
 * scan can have changed (the laser's cell +- max_range / resolution), so
 * g->prob is current after each call, as in CARMEN; finish runs on g->prob.
 * cpu_double, cpu_threads and cuda_exact keep CARMEN's bytes. Write cells
 * only through these functions while a backend other than cpu_double is in
 * use (the session would not see the writes).
 * carmen_mapper_update_evidence_grid_general runs on the CPU oracle, and the
 * grid stays there from then on. A backend that cannot start (no GPU) is
 * reported on stderr and the grid runs on the oracle. */
int vasco_egrid_set_backend(const char *backend);

/* vasco_gpu extension: the backend `grid` runs on now ("cpu_double" for the
 * oracle, "cpu_threads", "cpu_float", "cuda_float", "cuda_exact"). */
const char *vasco_egrid_grid_backend(const evidence_grid *grid);

/* vasco_gpu extension: 1 where carmen_mapper_finish_evidence_grid(grid,
 * downsample, border) would stop the process (a grid that mapped nothing, as
 * above), else 0: a program may test it and say so its own way. */
int vasco_egrid_finish_would_stop(const evidence_grid *grid, int downsample, int border);

#ifdef __cplusplus
}
#endif
#endif /* EGRID_H */
