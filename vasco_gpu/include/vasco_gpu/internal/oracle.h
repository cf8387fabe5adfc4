// oracle.h — the pieces of CARMEN's evidence-grid update that run on the
// host in double precision, shared by the cpu_double backend, the egrid C
// API and the CUDA backend's exact mode (which takes its beam end cells from
// here, so they come from the oracle's own code and the host's libm).
#ifndef VASCO_GPU_ORACLE_H
#define VASCO_GPU_ORACLE_H

#include <cmath>
#include <cstdint>

#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace oracle {

// The part of an evidence grid's state that places a pose in the grid.
struct GridFrame {
  int size_x = 0, size_y = 0;
  double resolution = 0;
  double theta_offset = 0;
  bool first = true;                              // no update yet
  double start_x = 0, start_y = 0, start_theta = 0;  // recorded by the first update
};

// A scan's pose in grid units (DESIGN §2 step 3).
struct ScanStart {
  double lx, ly;   // laser position in (fractional) cells
  double theta;    // laser heading in the grid frame
  int x1, y1;      // start cell: floor of (lx, ly)
};

// Places a pose; the first call records the start pose in `frame`.
inline ScanStart scan_start(GridFrame &frame, double x, double y, double theta) {
  if (frame.first) {
    frame.start_x = x / frame.resolution;
    frame.start_y = y / frame.resolution;
    frame.start_theta = theta;
    frame.first = false;
  }
  const double c = frame.theta_offset - frame.start_theta;
  const double cos_c = std::cos(c), sin_c = std::sin(c);
  const double xr = x * cos_c - y * sin_c;
  const double yr = x * sin_c + y * cos_c;
  ScanStart s;
  s.theta = theta + c;
  s.lx = frame.size_x / 2.0 + (xr / frame.resolution - frame.start_x);
  s.ly = frame.size_y / 2.0 + (yr / frame.resolution - frame.start_y);
  s.x1 = egrid::trunc_to_int(std::floor(s.lx));
  s.y1 = egrid::trunc_to_int(std::floor(s.ly));
  return s;
}

// Whether a beam is used at all (egrid_math.h).
inline bool beam_used(float range) { return egrid::is_beam_used(range); }

// The beam's end cell (DESIGN §2 step 5): (int) truncation, not floor.
inline void beam_end(const ScanStart &s, double angle, float range, double wall,
                     double resolution, int *x2, int *y2) {
  const double r = range;
  *x2 = egrid::trunc_to_int(s.lx + (r + wall) * std::cos(angle) / resolution);
  *y2 = egrid::trunc_to_int(s.ly + (r + wall) * std::sin(angle) / resolution);
}

// Number of distance-table entries per axis: (int)(max_range / resolution).
inline int distance_table_size(double max_range, double resolution) {
  return egrid::trunc_to_int(max_range / resolution);
}

// The distance table is built, as in CARMEN, only up to this many entries per
// axis (128 MiB of doubles); above it every backend computes the distance on
// the fly, which gives the same value, instead of allocating size^2 entries
// (8 GiB at the largest table_size the parameters allow).
constexpr int kMaxBuiltDistanceTable = 4096;

// Walks one beam and applies its updates to `cells` (x-major, size_y per
// column), exactly as egrid.c does.
//
// The walk is cut after `table_size` steps. This changes nothing: after k
// steps the current cell is k cells from the start along the major axis, so
// from step table_size on every cell has d = 1e6 >= max_range; a cell inside
// the grid then stops the beam and a cell outside is skipped, so no later cell
// is ever updated. The cut only bounds the work of degenerate beams (a range
// of -inf gives an end cell 2^31 cells away, which CARMEN walks cell by cell).
// `distance_table` may be null: the distance is then computed on the fly,
// which gives the same double.
// Fills CARMEN's distance table: rows[i][j] = sqrt(i*i + j*j) * resolution
// for 0 <= i, j < size (egrid.c's, built by every CPU user of the oracle).
inline void fill_distance_table(double *const *rows, int size, double resolution) {
  for (int i = 0; i < size; ++i)
    for (int j = 0; j < size; ++j) rows[i][j] = egrid::cell_distance(i, j, resolution);
}

// The distance CARMEN looks up for a cell i, j cells from the start: the
// table's value, 1e6 beyond it (an i or j of INT_MIN, which CARMEN's abs()
// gives for a wrapped coordinate, counts as beyond). `table` may be null: the
// same double is then computed.
inline double table_distance(int i, int j, int table_size, const double *const *table, double resolution) {
  if (i >= table_size || j >= table_size || i < 0 || j < 0) return egrid::kFarDistance;
  return table != nullptr ? table[i][j] : egrid::cell_distance(i, j, resolution);
}

inline long trace_beam(float *cells, int size_x, int size_y, int x1, int y1, int x2, int y2,
                       double range, const egrid::SensorModel<double> &model, double resolution,
                       int table_size, const double *const *distance_table) {
  long updates = 0;
  egrid::walk_beam_cells(x1, y1, x2, y2, table_size, size_x, size_y, [&](int cx, int cy, int i, int j) {
    double p;
    if (!egrid::sensor_model(model, table_distance(i, j, table_size, distance_table, resolution), range, &p))
      return false;
    float &cell = cells[egrid::cell_index(cx, cy, size_y)];
    cell = egrid::odds_update(cell, model.prior, p);
    ++updates;
    return true;
  });
  return updates;
}

// Beam angles of carmen_mapper_update_evidence_grid: theta + first, then
// `step` added after every beam (repeated addition, not i * step).
struct SteppedAngles {
  double first, step;
  bool started = false;
  void operator()(int, double theta, double *angle) {
    if (!started) {
      *angle = theta + first;
      started = true;
    } else {
      *angle += step;
    }
  }
};

struct ScanUpdateCounts {
  long beams_used = 0, beams_skipped = 0, cell_updates = 0;
};

// One scan of the oracle (carmen_mapper_update_evidence_grid{,_general}):
// places the pose, then traces every used beam in order. angle_of(i, theta,
// &angle) yields beam i's angle. `table` may be null (distances on the fly).
template <class AngleOf>
inline ScanUpdateCounts update_scan(float *cells, GridFrame &frame, const egrid::SensorModel<double> &model,
                                    double wall, int table_size, const double *const *table,
                                    double x, double y, double theta, int n, const float *range,
                                    AngleOf &&angle_of) {
  ScanUpdateCounts c;
  const ScanStart s = scan_start(frame, x, y, theta);
  double angle = 0;
  for (int i = 0; i < n; ++i) {
    angle_of(i, s.theta, &angle);
    if (!beam_used(range[i])) {
      ++c.beams_skipped;
      continue;
    }
    ++c.beams_used;
    int x2, y2;
    beam_end(s, angle, range[i], wall, frame.resolution, &x2, &y2);
    c.cell_updates += trace_beam(cells, frame.size_x, frame.size_y, s.x1, s.y1, x2, y2, range[i],
                                 model, frame.resolution, table_size, table);
  }
  return c;
}

}  // namespace oracle
}  // namespace vasco

#endif  // VASCO_GPU_ORACLE_H
