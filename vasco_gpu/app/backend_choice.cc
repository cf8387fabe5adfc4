#include "backend_choice.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vasco_gpu/internal/egrid_math.h"

namespace log2map {

namespace {

// Measured on an H200 host (16 cores, CUDA 13) by `python3 bench/batch_bench.py`
// (its last table; README "Choosing a backend"): one core of cpu_threads
// updates about 7.0e7 cells a second on fr101 (3.0e8 cells in 0.27 s on 16
// cores; the threads scale close to linearly: the grid is split into
// stripes with no shared cell), the GPU 2.3e10 once running (float mode;
// exact mode is within 2x), and its start-up in one process (context and
// module) costs 0.29 s of wall-clock time. Another host's cores may be
// faster or slower (a 2-core development machine measured 9e7): batch_bench
// prints its values; a wrong rate moves the choice only for logs on which
// both backends take about as long.
constexpr double kCpuCellsPerCoreSecond = 7.0e7;
constexpr double kGpuStartSeconds = 0.29;
constexpr double kGpuCellsPerSecond = 2.3e10;

}  // namespace

double estimated_cell_updates(const vasco::ScanBatch &scans, const vasco::MapperParams &params) {
  double cells = 0;
  const double reach = params.range_max;
  for (float r : scans.range) {
    if (!vasco::egrid::is_beam_used(r)) continue;
    const double length = std::min(static_cast<double>(r) + params.wall_size, reach);
    if (length > 0) cells += length / params.resolution + 1;
  }
  return cells;
}

BackendChoice choose_backend(double cell_updates, int cores) {
  BackendChoice c;
  cores = std::max(cores, 1);
  c.cpu_s = cell_updates / (kCpuCellsPerCoreSecond * cores);
  const double gpu_map_s = cell_updates / kGpuCellsPerSecond;
  c.gpu_s = kGpuStartSeconds + gpu_map_s;
  c.gpu = c.gpu_s < c.cpu_s;
  char text[200];
  std::snprintf(text, sizeof text, "%.2g cell updates: about %.3f s on %d cores, %.3f s on the GPU (%.2f s of it start-up)",
                cell_updates, c.cpu_s, cores, c.gpu_s, kGpuStartSeconds);
  c.why = text;
  return c;
}

}  // namespace log2map
