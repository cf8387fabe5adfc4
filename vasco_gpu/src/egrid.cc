// CARMEN's evidence-grid C API on top of the oracle (oracle.h, grid.h).
#include "carmen/egrid.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

#include "vasco_gpu/grid.h"
#include "vasco_gpu/oracle.h"

namespace {

float **alloc_columns(int size_x, int size_y) {
  const size_t n = static_cast<size_t>(size_x) * static_cast<size_t>(size_y);
  float *block = static_cast<float *>(std::malloc(n ? n * sizeof(float) : 1));
  float **cols = static_cast<float **>(std::malloc((size_x ? size_x : 1) * sizeof(float *)));
  if (block == nullptr || cols == nullptr) {
    std::free(block);
    std::free(cols);
    return nullptr;
  }
  for (int x = 0; x < size_x; ++x) cols[x] = block + static_cast<size_t>(x) * size_y;
  if (size_x == 0) cols[0] = block;
  return cols;
}

void free_columns(float **cols) {
  if (cols != nullptr) {
    std::free(cols[0]);
    std::free(cols);
  }
}

void free_table(evidence_grid *g) {
  if (g->distance_table != nullptr) {
    std::free(g->distance_table[0]);
    std::free(g->distance_table);
    g->distance_table = nullptr;
  }
}

vasco::oracle::GridFrame frame_of(const evidence_grid *g) {
  vasco::oracle::GridFrame f;
  f.size_x = g->size_x;
  f.size_y = g->size_y;
  f.resolution = g->resolution;
  f.theta_offset = g->theta_offset;
  f.first = g->first != 0;
  f.start_x = g->start_x;
  f.start_y = g->start_y;
  f.start_theta = g->start_theta;
  return f;
}

void store_frame(evidence_grid *g, const vasco::oracle::GridFrame &f) {
  g->first = f.first ? 1 : 0;
  g->start_x = f.start_x;
  g->start_y = f.start_y;
  g->start_theta = f.start_theta;
}

vasco::egrid::ModelParams model_of(const evidence_grid *g) {
  return {g->prior_occ, g->occ_evidence, g->emp_evidence, g->max_sure_range, g->max_range};
}

// The update shared by both entry points.
template <class AngleOf>
void update(evidence_grid *g, double x, double y, double theta, int n, const float *range,
            AngleOf &&angle_of) {
  if (g == nullptr || g->prob == nullptr) return;
  if (n < 0 || (n > 0 && range == nullptr)) return;
  vasco::oracle::GridFrame frame = frame_of(g);
  vasco::oracle::update_scan(g->prob[0], frame, model_of(g), g->wall_thickness,
                             g->distance_table_size, g->distance_table, x, y, theta, n, range,
                             angle_of);
  store_frame(g, frame);
}

}  // namespace

extern "C" {

void carmen_mapper_initialize_evidence_grid(evidence_grid *grid, int size_x, int size_y,
                                            double resolution, double theta_offset,
                                            double prior_occ, double occ_evidence,
                                            double emp_evidence, double max_prob,
                                            double max_sure_range, double max_range,
                                            double wall_thickness) {
  if (grid == nullptr) {
    std::fprintf(stderr, "carmen_mapper_initialize_evidence_grid: grid is NULL\n");
    return;
  }
  std::memset(grid, 0, sizeof(*grid));
  grid->resolution = resolution;
  grid->size_x = size_x;
  grid->size_y = size_y;
  grid->theta_offset = theta_offset;
  grid->prior_occ = prior_occ;
  grid->occ_evidence = occ_evidence;
  grid->emp_evidence = emp_evidence;
  grid->max_prob = max_prob;
  grid->max_sure_range = max_sure_range;
  grid->max_range = max_range;
  grid->wall_thickness = wall_thickness;
  grid->first = 1;
  if (size_x <= 0 || size_y <= 0 || !(resolution > 0)) {
    std::fprintf(stderr, "carmen_mapper_initialize_evidence_grid: bad size %d x %d or resolution %g\n",
                 size_x, size_y, resolution);
    return;
  }
  grid->prob = alloc_columns(size_x, size_y);
  if (grid->prob == nullptr) {
    std::fprintf(stderr, "carmen_mapper_initialize_evidence_grid: cannot allocate %d x %d cells\n",
                 size_x, size_y);
    return;
  }
  const size_t n = static_cast<size_t>(size_x) * size_y;
  for (size_t i = 0; i < n; ++i) grid->prob[0][i] = vasco::egrid::kUnknown;

  const int t = vasco::oracle::distance_table_size(max_range, resolution);
  grid->distance_table_size = t > 0 ? t : 0;
  if (t > 0 && t <= vasco::oracle::kMaxBuiltDistanceTable) {  // else NULL: on the fly
    const size_t tn = static_cast<size_t>(t);
    double *block = static_cast<double *>(std::malloc(tn * tn * sizeof(double)));
    double **rows = static_cast<double **>(std::malloc(tn * sizeof(double *)));
    if (block != nullptr && rows != nullptr) {
      for (int i = 0; i < t; ++i) {
        rows[i] = block + static_cast<size_t>(i) * tn;
        for (int j = 0; j < t; ++j) rows[i][j] = vasco::egrid::cell_distance(i, j, resolution);
      }
      grid->distance_table = rows;
    } else {
      std::free(block);
      std::free(rows);
    }
  }
}

void carmen_mapper_update_evidence_grid(evidence_grid *grid, double laser_x, double laser_y,
                                        double laser_theta, int num_readings, float *laser_range,
                                        double angular_resolution, double first_beam_angle) {
  update(grid, laser_x, laser_y, laser_theta, num_readings, laser_range,
         vasco::oracle::SteppedAngles{first_beam_angle, angular_resolution});
}

void carmen_mapper_update_evidence_grid_general(evidence_grid *grid, double laser_x,
                                                double laser_y, double laser_theta,
                                                int num_readings, float *laser_range,
                                                float *laser_angle) {
  if (laser_angle == nullptr) return;
  update(grid, laser_x, laser_y, laser_theta, num_readings, laser_range,
         [&](int i, double theta, double *angle) { *angle = theta + laser_angle[i]; });
}

void carmen_mapper_clear_evidence_grid(evidence_grid *grid) {
  if (grid == nullptr || grid->prob == nullptr) return;
  const size_t n = static_cast<size_t>(grid->size_x) * grid->size_y;
  const float prior = static_cast<float>(grid->prior_occ);
  for (size_t i = 0; i < n; ++i) grid->prob[0][i] = prior;
}

void carmen_mapper_finish_evidence_grid(evidence_grid *grid, int downsample, int border) {
  if (grid == nullptr || grid->prob == nullptr) return;
  vasco::FinishedMap m;
  try {
    m = vasco::finish_grid(grid->prob[0], grid->size_x, grid->size_y, grid->resolution, downsample,
                           border);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "carmen_mapper_finish_evidence_grid: %s\n", e.what());
    return;
  }
  float **cols = alloc_columns(m.size_x, m.size_y);
  if (cols == nullptr) {
    std::fprintf(stderr, "carmen_mapper_finish_evidence_grid: out of memory\n");
    return;
  }
  if (!m.cells.empty()) std::memcpy(cols[0], m.cells.data(), m.cells.size() * sizeof(float));
  free_columns(grid->prob);
  grid->prob = cols;
  grid->size_x = m.size_x;
  grid->size_y = m.size_y;
  grid->resolution = m.resolution;
}

void carmen_mapper_free_evidence_grid(evidence_grid *grid) {
  if (grid == nullptr) return;
  free_columns(grid->prob);
  grid->prob = nullptr;
  free_table(grid);
}

}  // extern "C"
