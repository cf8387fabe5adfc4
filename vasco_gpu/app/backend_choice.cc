#include "backend_choice.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vasco_gpu/internal/egrid_math.h"

namespace log2map {

namespace {

// Read from the measured table backend_cost_model.txt (its header names the
// run; vasco_gpu/app/CMakeLists.txt passes each line here): one core of
// cpu_threads' cell updates a second (the threads scale close to linearly:
// the grid is split into stripes with no shared cell), the GPU's once
// running (float mode; exact mode is within 2x), and its start-up in one
// process (context and module) in wall-clock seconds. Another host's cores
// may be faster or slower: batch_bench prints its values; a wrong rate moves
// the choice only for logs on which both backends take about as long.
#if !defined(VASCO_COST_CPU_CELLS_PER_CORE_SECOND) || !defined(VASCO_COST_GPU_CELLS_PER_SECOND) || \
    !defined(VASCO_COST_GPU_START_SECONDS)
#error "backend_cost_model.txt lacks a constant of auto's cost model"
#endif
constexpr double kCpuCellsPerCoreSecond = VASCO_COST_CPU_CELLS_PER_CORE_SECOND;
constexpr double kGpuStartSeconds = VASCO_COST_GPU_START_SECONDS;
constexpr double kGpuCellsPerSecond = VASCO_COST_GPU_CELLS_PER_SECOND;

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
