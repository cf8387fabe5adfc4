/* mapper_c.h — the mapping session (vasco::Mapper, DESIGN §7) from C and other
 * languages: an opaque handle, plain C types, status codes and a message.
 *
 *   vasco_mapper_params p;
 *   vasco_mapper_params_default(&p);
 *   vasco_mapper *m;
 *   if (vasco_mapper_create(&p, "cuda", &m) != VASCO_OK) { ... vasco_last_error(NULL) ... }
 *   vasco_mapper_insert(m, n, poses, beam_counts, ranges, first_angles, angle_steps);
 *   vasco_mapper_render(m, n_all, new_poses);          // after a loop closure
 *   vasco_map map;
 *   vasco_mapper_finish(m, p.downsample, p.border, &map);  // map.cells valid until the next call on m
 *   vasco_mapper_destroy(m);
 *
 * Poses are (x, y, theta) triples of the laser in the world frame, one per
 * scan. Ranges are the scans' beams one after another (beam_counts[s] for
 * scan s); beam i of scan s points at theta + first_angles[s] + i *
 * angle_steps[s], accumulated by repeated addition as CARMEN does. The frame
 * is the golden PROTOCOL's (centred on the first scan, grown as scans arrive,
 * see vasco_gpu/mapper.hpp), or fixed with vasco_mapper_create_fixed.
 * Functions return VASCO_OK or an error code; vasco_last_error(m) says what
 * went wrong in the last failed call on m (with m NULL: in this thread's
 * last failed create). A failed call leaves the session as it was.
 *
 * Threads: every call on a handle takes the handle's lock, so one handle may
 * be used from several threads (calls run one at a time, in the order they
 * get the lock). What a call hands out — the cells of vasco_mapper_finish,
 * the text of vasco_last_error — stays valid until the next call on the
 * handle from any thread: threads sharing a handle copy it before they let
 * another call run. vasco_mapper_destroy must not overlap another call. */
#ifndef VASCO_GPU_MAPPER_C_H
#define VASCO_GPU_MAPPER_C_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vasco_mapper vasco_mapper;

typedef enum {
  VASCO_OK = 0,
  VASCO_ERR_INVALID_ARGUMENT = 1, /* a NULL pointer, a bad parameter, a window outside the grid */
  VASCO_ERR_BACKEND = 2,          /* unknown backend, or it cannot run here (no GPU) */
  VASCO_ERR_OUT_OF_MEMORY = 3,
  VASCO_ERR_TOO_LARGE = 4,        /* the poses span a grid beyond the size limit */
  VASCO_ERR_STATE = 5,            /* e.g. finish before any scan was inserted */
  VASCO_ERR_INTERNAL = 6,
  VASCO_ERR_IO = 7                /* the file system refused (open, write, rename) */
} vasco_status;

typedef struct {
  double resolution, p_prior, p_occ, p_emp, range_sure, range_max, wall_size;
  int downsample, border;
} vasco_mapper_params;

/* A map owned by its mapper: cells x-major (cells[x * size_y + y]), -1 unknown. */
typedef struct {
  int size_x, size_y;
  double resolution;
  int offset_x, offset_y; /* the crop's first cell, in downsampled cells of the full grid */
  const float *cells;
} vasco_map;

/* vasco's defaults (resolution 0.025 m, p_occ 0.55, ...; downsample 4, border 20). */
void vasco_mapper_params_default(vasco_mapper_params *params);

/* backend: "cpu_double", "cpu_threads", "cpu_float", "cuda" (float mode),
 * "cuda_exact", or "auto"; NULL means "cpu_double". "auto" chooses cuda or
 * cpu_threads at the first insert, by that insert's scans mapped once
 * (vasco_gpu/backend_choice.h: the rule log2map --backend auto follows). */
vasco_status vasco_mapper_create(const vasco_mapper_params *params, const char *backend, vasco_mapper **out);
/* A fixed frame of size_x x size_y cells with heading theta_offset, centred
 * on the first scan, as CARMEN's carmen_mapper_initialize_evidence_grid. */
vasco_status vasco_mapper_create_fixed(const vasco_mapper_params *params, const char *backend, int size_x,
                                       int size_y, double theta_offset, vasco_mapper **out);
void vasco_mapper_destroy(vasco_mapper *m);
/* The host-memory budget of the session in bytes (0: none; by default the
 * session option max_memory's, kDefaultMaxMemoryBytes in vasco_gpu/backend.h).
 * An insert or render that would need more fails with VASCO_ERR_OUT_OF_MEMORY
 * and changes nothing; so does this call, keeping the old budget, when the
 * session already needs more than `bytes`. */
vasco_status vasco_mapper_set_max_memory(vasco_mapper *m, unsigned long long bytes);

vasco_status vasco_mapper_insert(vasco_mapper *m, size_t num_scans, const double *poses,
                                 const int *beam_counts, const float *ranges, const double *first_angles,
                                 const double *angle_steps);
/* New poses (num_scans == vasco_mapper_num_scans) and the grid recomputed. */
vasco_status vasco_mapper_render(vasco_mapper *m, size_t num_scans, const double *poses);
vasco_status vasco_mapper_finish(vasco_mapper *m, int downsample, int border, vasco_map *out);
/* The full-resolution grid's size, and a window of it into out[width * height]
 * (x-major; out may be NULL when width or height is 0). */
vasco_status vasco_mapper_grid_size(const vasco_mapper *m, int *size_x, int *size_y);
vasco_status vasco_mapper_read(vasco_mapper *m, int x0, int y0, int width, int height, float *out);
size_t vasco_mapper_num_scans(const vasco_mapper *m);

const char *vasco_last_error(const vasco_mapper *m);

#ifdef __cplusplus
}
#endif
#endif /* VASCO_GPU_MAPPER_C_H */
