#include "backend_choice.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vasco_gpu/internal/egrid_math.h"

namespace log2map {

namespace {

// Measured on an H200 host (16 cores) with `log2map --json` (seconds.map
// against cell_updates) over the bundled logs; see the README's
// "Choosing a backend". One core of cpu_threads updates about this many
// cells a second (the threads scale close to linearly: the grid is split
// into stripes with no shared cell).
constexpr double kCpuCellsPerCoreSecond = 6.0e7;
// The GPU: start-up of a process's first CUDA use (context and module) and
// cells a second once running (float mode; exact mode is within 2x).
constexpr double kGpuStartSeconds = 0.28;
constexpr double kGpuCellsPerSecond = 2.0e10;

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
