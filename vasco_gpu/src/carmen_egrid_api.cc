// CARMEN's evidence-grid C API: on the oracle (oracle.h, grid.h) by default,
// or on a mapping session of another backend (vasco_egrid_set_backend,
// VASCO_GPU_BACKEND), g->prob being brought up to date after every update.
#include "carmen/egrid.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <vector>

#include "vasco_gpu/backend.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/mapper.hpp"
#include "vasco_gpu/internal/oracle.h"

namespace {

// ---------------------------------------------------------------------------
// Sessions: the mapping session behind a grid that runs on another backend.
// The C struct is CARMEN's and has no room for one, so they live here, keyed
// by the grid's address.
// ---------------------------------------------------------------------------
struct Session {
  std::unique_ptr<vasco::Mapper> mapper;
  bool cleared = false;  // cells the session calls unknown are prior_occ in g->prob
  bool has_first = false;
  vasco::Pose first;     // the first update's pose, as given: CARMEN's start pose
};

std::mutex sessions_mutex;
std::map<const evidence_grid *, std::unique_ptr<Session>> &sessions() {
  static std::map<const evidence_grid *, std::unique_ptr<Session>> s;
  return s;
}

std::string &chosen_backend() {
  static std::string b;
  return b;
}

// A name of the backend registry, as a string that lives as long as the
// program (what vasco_egrid_grid_backend returns); null for an unknown name.
const char *registry_name(const std::string &b) {
  const vasco::BackendInfo *info = vasco::find_backend(b);
  if (info == nullptr) return nullptr;
  for (const vasco::BackendAlias &a : info->aliases)
    if (b == a.name) return a.name;
  return info->name;
}

// The backend for a grid initialised now: the call's, else the environment's.
std::string backend_for_new_grid() {
  std::lock_guard<std::mutex> lock(sessions_mutex);
  if (!chosen_backend().empty()) return chosen_backend();
  const char *env = std::getenv("VASCO_GPU_BACKEND");
  return env != nullptr ? env : "cpu_double";
}

Session *session_of(const evidence_grid *g) {
  std::lock_guard<std::mutex> lock(sessions_mutex);
  auto it = sessions().find(g);
  return it == sessions().end() ? nullptr : it->second.get();
}

void drop_session(const evidence_grid *g) {
  std::lock_guard<std::mutex> lock(sessions_mutex);
  sessions().erase(g);
}

vasco::MapperParams mapper_params_of(const evidence_grid *g) {
  vasco::MapperParams p;
  p.resolution = g->resolution;
  p.p_prior = g->prior_occ;
  p.p_occ = g->occ_evidence;
  p.p_emp = g->emp_evidence;
  p.range_sure = g->max_sure_range;
  p.range_max = g->max_range;
  p.wall_size = g->wall_thickness;
  p.max_prob = g->max_prob;
  return p;
}

// A session for a freshly initialised (or cleared) grid, or none for the
// oracle. `anchor`: the start pose CARMEN recorded before a clear, given to
// the session as a scan without beams so that it keeps fixing the frame.
std::unique_ptr<Session> open_session(const evidence_grid *g, const std::string &backend,
                                      const vasco::Pose *anchor) {
  if (backend == "cpu_double") return nullptr;
  try {
    vasco::BackendOptions opt;
    opt.expected_renders = 0;  // scans mapped as they come: a workload without end (backend_choice.h)
    const std::string name = vasco::resolve_backend_name(backend, &opt);
    vasco::GridGeometry frame;
    frame.size_x = g->size_x;
    frame.size_y = g->size_y;
    frame.resolution = g->resolution;
    frame.theta_offset = g->theta_offset;
    auto s = std::make_unique<Session>();
    s->mapper = std::make_unique<vasco::Mapper>(mapper_params_of(g), frame, name, opt);
    if (anchor != nullptr) {
      vasco::ScanBatch start;
      start.add_scan(anchor->x, anchor->y, anchor->theta, 0, 0, nullptr, 0, 0);
      s->mapper->insert(start);
      s->has_first = true;
      s->first = *anchor;
    }
    return s;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "carmen_mapper_initialize_evidence_grid: backend %s: %s; using the CPU oracle\n",
                 backend.c_str(), e.what());
    return nullptr;
  }
}

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

vasco::egrid::SensorModel<double> model_of(const evidence_grid *g) {
  return {g->prior_occ, g->occ_evidence, g->emp_evidence, g->max_sure_range, g->max_range};
}

// The update shared by both entry points, on the oracle.
template <class AngleOf>
void update(const char *who, evidence_grid *g, double x, double y, double theta, int n, const float *range,
            AngleOf &&angle_of) {
  if (g == nullptr || g->prob == nullptr) {  // a failed allocation was reported when it happened
    if (g == nullptr) std::fprintf(stderr, "%s: grid is NULL: scan ignored\n", who);
    return;
  }
  if (n < 0 || (n > 0 && range == nullptr)) {
    std::fprintf(stderr, "%s: %d readings%s: scan ignored\n", who, n, n > 0 ? " and laser_range NULL" : "");
    return;
  }
  vasco::oracle::GridFrame frame = frame_of(g);
  vasco::oracle::update_scan(g->prob[0], frame, model_of(g), g->wall_thickness,
                             g->distance_table_size, g->distance_table, x, y, theta, n, range,
                             angle_of);
  store_frame(g, frame);
}

// The update on a session: the scan goes to the mapper, then the square of
// cells it can have changed comes back into g->prob. A cell the walk updates
// is fewer than table_size steps from the laser's cell, and each step moves
// each coordinate by at most one, so the square is the laser's cell +-
// (table_size - 1), clipped to the grid.
void update_on_session(evidence_grid *g, Session &s, double x, double y, double theta, int n,
                       const float *range, double step, double first_angle) {
  vasco::ScanBatch scan;
  scan.add_scan(x, y, theta, first_angle, step, range, n, 0);
  s.mapper->insert(scan);
  if (!s.has_first) s.has_first = true, s.first = {x, y, theta};
  vasco::oracle::GridFrame frame = frame_of(g);
  const vasco::oracle::ScanStart start = vasco::oracle::scan_start(frame, x, y, theta);
  store_frame(g, frame);
  const int reach = std::max(g->distance_table_size - 1, 0);
  const long x0 = std::max<long>(0, static_cast<long>(start.x1) - reach);
  const long x1 = std::min<long>(g->size_x - 1, static_cast<long>(start.x1) + reach);
  const long y0 = std::max<long>(0, static_cast<long>(start.y1) - reach);
  const long y1 = std::min<long>(g->size_y - 1, static_cast<long>(start.y1) + reach);
  if (x0 > x1 || y0 > y1) return;
  const vasco::GridWindow w{static_cast<int>(x0), static_cast<int>(y0), static_cast<int>(x1 - x0 + 1),
                            static_cast<int>(y1 - y0 + 1)};
  const std::vector<float> cells = s.mapper->read(w);
  const float prior = static_cast<float>(g->prior_occ);
  for (int i = 0; i < w.width; ++i) {
    const float *col = cells.data() + static_cast<size_t>(i) * w.height;
    float *dst = g->prob[w.x0 + i] + w.y0;
    for (int j = 0; j < w.height; ++j) dst[j] = (s.cleared && col[j] == vasco::egrid::kUnknown) ? prior : col[j];
  }
}

// CARMEN's finish of a grid without a known block: its bounds start at
// (n - border - 1, border), nothing widens them, and for n > 4 border + 1
// blocks the size max - min comes out negative; CARMEN's allocation of it
// fails and it dies "Out of memory" before its caller writes a map. True
// when CARMEN would: the caller must not go on to write a header without a
// grid (the half-written map file of a run that mapped nothing).
bool carmen_dies_finishing(const evidence_grid *g, int downsample, int border) {
  if (downsample < 1 || border < 0) return false;  // refused with its own message
  const int64_t nx = g->size_x / downsample, ny = g->size_y / downsample;
  const int64_t widest = 4 * static_cast<int64_t>(border) + 1;
  if (nx <= widest && ny <= widest) return false;
  for (int64_t x = 0; x < nx * downsample; ++x)
    for (int64_t y = 0; y < ny * downsample; ++y)
      if (g->prob[x][y] != -1.0f) return false;
  return true;
}

}  // namespace

extern "C" {

int carmen_mapper_initialize_evidence_grid(evidence_grid *grid, int size_x, int size_y,
                                           double resolution, double theta_offset,
                                           double prior_occ, double occ_evidence,
                                           double emp_evidence, double max_prob,
                                           double max_sure_range, double max_range,
                                           double wall_thickness) {
  if (grid == nullptr) {
    std::fprintf(stderr, "carmen_mapper_initialize_evidence_grid: grid is NULL\n");
    return -1;
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
    return -1;
  }
  grid->prob = alloc_columns(size_x, size_y);
  if (grid->prob == nullptr) {
    std::fprintf(stderr, "carmen_mapper_initialize_evidence_grid: cannot allocate %d x %d cells\n",
                 size_x, size_y);
    return -1;
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
      for (int i = 0; i < t; ++i) rows[i] = block + static_cast<size_t>(i) * tn;
      vasco::oracle::fill_distance_table(rows, t, resolution);
      grid->distance_table = rows;
    } else {
      std::free(block);
      std::free(rows);
    }
  }
  drop_session(grid);  // a grid re-initialised without a free
  std::unique_ptr<Session> s = open_session(grid, backend_for_new_grid(), nullptr);
  if (s) {
    std::lock_guard<std::mutex> lock(sessions_mutex);
    sessions()[grid] = std::move(s);
  }
  return 0;
}

void carmen_mapper_update_evidence_grid(evidence_grid *grid, double laser_x, double laser_y,
                                        double laser_theta, int num_readings, float *laser_range,
                                        double angular_resolution, double first_beam_angle) {
  Session *s = session_of(grid);
  if (s != nullptr && grid->prob != nullptr && num_readings >= 0 && (num_readings == 0 || laser_range != nullptr)) {
    try {
      update_on_session(grid, *s, laser_x, laser_y, laser_theta, num_readings, laser_range, angular_resolution,
                        first_beam_angle);
      return;
    } catch (const std::exception &e) {
      // g->prob holds every update before this one: the oracle carries on.
      std::fprintf(stderr, "carmen_mapper_update_evidence_grid: %s; continuing on the CPU oracle\n", e.what());
      drop_session(grid);
    }
  }
  update("carmen_mapper_update_evidence_grid", grid, laser_x, laser_y, laser_theta, num_readings, laser_range,
         vasco::oracle::SteppedAngles{first_beam_angle, angular_resolution});
}

void carmen_mapper_update_evidence_grid_general(evidence_grid *grid, double laser_x,
                                                double laser_y, double laser_theta,
                                                int num_readings, float *laser_range,
                                                float *laser_angle, double /*angular_resolution*/,
                                                double /*first_beam_angle*/) {
  if (laser_angle == nullptr) {
    if (num_readings != 0)
      std::fprintf(stderr, "carmen_mapper_update_evidence_grid_general: %d readings and laser_angle NULL: scan "
                           "ignored\n", num_readings);
    return;
  }
  drop_session(grid);  // per-beam angles: the oracle, from now on (g->prob is current)
  update("carmen_mapper_update_evidence_grid_general", grid, laser_x, laser_y, laser_theta, num_readings, laser_range,
         [&](int i, double theta, double *angle) { *angle = theta + laser_angle[i]; });
}

void carmen_mapper_clear_evidence_grid(evidence_grid *grid) {
  if (grid == nullptr || grid->prob == nullptr) return;
  const size_t n = static_cast<size_t>(grid->size_x) * grid->size_y;
  const float prior = static_cast<float>(grid->prior_occ);
  for (size_t i = 0; i < n; ++i) grid->prob[0][i] = prior;
  // A session starts over; CARMEN keeps the start pose, so the new one is
  // anchored on it.
  Session *s = session_of(grid);
  if (s != nullptr) {
    const std::string backend = s->mapper->backend_name();
    const bool has_first = s->has_first;
    const vasco::Pose first = s->first;
    drop_session(grid);
    std::unique_ptr<Session> fresh = open_session(grid, backend,
                                                  has_first ? &first : nullptr);
    if (fresh) {
      fresh->cleared = true;
      std::lock_guard<std::mutex> lock(sessions_mutex);
      sessions()[grid] = std::move(fresh);
    }
  }
}

void carmen_mapper_finish_evidence_grid(evidence_grid *grid, int downsample, int border) {
  if (grid == nullptr || grid->prob == nullptr) return;
  drop_session(grid);  // g->prob is current; the finished grid is CARMEN's alone
  if (carmen_dies_finishing(grid, downsample, border)) {
    std::fprintf(stderr,
                 "carmen_mapper_finish_evidence_grid: no cell of the %d x %d grid was updated (an empty or "
                 "scan-less log?): there is no map to finish. CARMEN stops here (\"Out of memory\"); so does "
                 "this library, before a map file is begun\n",
                 grid->size_x, grid->size_y);
    std::exit(-1);  // carmen_die's status (255): scripts around CARMEN's programs check it
  }
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
  drop_session(grid);
  free_columns(grid->prob);
  grid->prob = nullptr;
  free_table(grid);
}

int vasco_egrid_set_backend(const char *backend) {
  if (backend == nullptr || (*backend != '\0' && registry_name(backend) == nullptr)) return -1;
  std::lock_guard<std::mutex> lock(sessions_mutex);
  chosen_backend() = backend;
  return 0;
}

int vasco_egrid_finish_would_stop(const evidence_grid *grid, int downsample, int border) {
  return grid != nullptr && grid->prob != nullptr && carmen_dies_finishing(grid, downsample, border) ? 1 : 0;
}

const char *vasco_egrid_grid_backend(const evidence_grid *grid) {
  const Session *s = session_of(grid);
  const char *name = s != nullptr ? registry_name(s->mapper->backend_name()) : nullptr;
  return name != nullptr ? name : "cpu_double";
}

}  // extern "C"
