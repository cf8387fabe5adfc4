/* egrid.h — CARMEN 0.7.4's evidence-grid API (vasco's libegrid), offered
 * unchanged: code written against vasco/egrid.h compiles and links against
 * vasco_gpu instead. The implementation is vasco_gpu's double-precision
 * oracle, which reproduces CARMEN's arithmetic bit for bit.
 *
 * Differences from CARMEN, all on input CARMEN would crash on:
 *  - allocation failure prints a message and leaves `prob` NULL (every later
 *    call is then a no-op) instead of exiting;
 *  - NULL pointers and negative sizes are rejected with a message. */
#ifndef CARMEN_EGRID_H
#define CARMEN_EGRID_H

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

void carmen_mapper_initialize_evidence_grid(evidence_grid *grid, int size_x, int size_y,
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

/* Beam i points at laser_theta + laser_angle[i]. */
void carmen_mapper_update_evidence_grid_general(evidence_grid *grid, double laser_x,
                                                double laser_y, double laser_theta,
                                                int num_readings, float *laser_range,
                                                float *laser_angle);

/* Every cell to the prior. */
void carmen_mapper_clear_evidence_grid(evidence_grid *grid);

/* Downsamples by `downsample` and crops to the known cells plus `border`
 * (DESIGN §2 step 7); size and resolution are updated in place. */
void carmen_mapper_finish_evidence_grid(evidence_grid *grid, int downsample, int border);

void carmen_mapper_free_evidence_grid(evidence_grid *grid);

#ifdef __cplusplus
}
#endif
#endif /* CARMEN_EGRID_H */
