// auto's rule (backend_choice.h): the backend expected to finish first.
#include "vasco_gpu/backend_choice.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "vasco_gpu/internal/egrid_math.h"
#include "vasco_gpu/internal/parallel.h"

namespace vasco {

namespace {

// Read from the measured table backend_cost_model.txt (its header names the
// run; vasco_gpu/CMakeLists.txt passes each line here): one core of
// cpu_threads' cell updates a second (the threads scale close to linearly:
// the grid is split into stripes with no shared cell), the GPU's once
// running, and its start-up in one process. Another host's cores may be
// faster or slower: batch_bench prints its values; a wrong rate moves the
// choice only for workloads on which both backends take about as long.
#if !defined(VASCO_COST_CPU_CELLS_PER_CORE_SECOND) || !defined(VASCO_COST_GPU_CELLS_PER_SECOND) || \
    !defined(VASCO_COST_GPU_START_SECONDS)
#error "backend_cost_model.txt lacks a constant of auto's cost model"
#endif
constexpr CostModel kMeasured = {VASCO_COST_CPU_CELLS_PER_CORE_SECOND, VASCO_COST_GPU_CELLS_PER_SECOND,
                                 VASCO_COST_GPU_START_SECONDS};

// The note for a workload without end: the rates alone decide.
std::string rates_note(const AutoChoice &c, const CostModel &m, const std::string &no_gpu) {
  char text[200];
  if (c.gpu_usable)
    std::snprintf(text, sizeof text, "many renders: %.2g cell updates a second on %d cores, %.2g on the GPU",
                  m.cpu_cells_per_core_second * c.cores, c.cores, m.gpu_cells_per_second);
  else
    std::snprintf(text, sizeof text, "many renders: %.2g cell updates a second on %d cores; %s",
                  m.cpu_cells_per_core_second * c.cores, c.cores, no_gpu.c_str());
  return text;
}

// The note for a known workload, N renders of it. With N = 1 the text is
// the one log2map has always printed.
std::string workload_note(const AutoChoice &c, const CostModel &m, const std::string &no_gpu) {
  char work[80], text[240];
  if (c.renders == 1)
    std::snprintf(work, sizeof work, "%.2g cell updates", c.cell_updates);
  else
    std::snprintf(work, sizeof work, "%.2g cell updates, %d renders", c.cell_updates, c.renders);
  if (c.gpu_usable)
    std::snprintf(text, sizeof text, "%s: about %.3f s on %d cores, %.3f s on the GPU (%.2f s of it start-up)", work,
                  c.cpu_s, c.cores, c.gpu_s, m.gpu_start_seconds);
  else
    std::snprintf(text, sizeof text, "%s: about %.3f s on %d cores; %s", work, c.cpu_s, c.cores, no_gpu.c_str());
  return text;
}

// Whether CUDA_VISIBLE_DEVICES hides every GPU: set empty, or its first
// entry an invalid index such as -1 (CUDA shows only the devices before the
// first invalid entry).
bool every_gpu_hidden() {
  const char *visible = std::getenv("CUDA_VISIBLE_DEVICES");
  return visible != nullptr && (visible[0] == '\0' || visible[0] == '-');
}

// Whether this process surely has no GPU, known without starting CUDA: a
// build without the cuda backend, a host where NVIDIA's kernel driver is
// not loaded, or every GPU hidden from it (then asking fails at once,
// without a context, and the note gives no GPU time).
bool no_gpu_at_no_cost() {
  const BackendInfo *cuda = find_backend("cuda");
  return cuda == nullptr || !cuda->compiled || ::access("/proc/driver/nvidia/version", F_OK) != 0 ||
         every_gpu_hidden();
}

}  // namespace

const CostModel &auto_cost_model() { return kMeasured; }

double estimated_cell_updates(const ScanBatch &scans, const MapperParams &params) {
  double cells = 0;
  const double reach = params.range_max;
  for (float r : scans.range) {
    if (!egrid::is_beam_used(r)) continue;
    const double length = std::min(static_cast<double>(r) + params.wall_size, reach);
    if (length > 0) cells += length / params.resolution + 1;
  }
  return cells;
}

AutoChoice choose_auto(double cell_updates, int cores, int renders, bool gpu_usable, const std::string &no_gpu) {
  const CostModel &m = auto_cost_model();
  AutoChoice c;
  c.cores = std::max(cores, 1);
  c.renders = std::max(renders, 0);
  c.cell_updates = cell_updates;
  c.gpu_usable = gpu_usable;
  const double cpu_rate = m.cpu_cells_per_core_second * c.cores;
  const double n = c.renders > 0 ? c.renders : 1;
  c.cpu_s = n * cell_updates / cpu_rate;
  c.gpu_s = n * cell_updates / m.gpu_cells_per_second + (c.renders > 0 ? m.gpu_start_seconds : 0);
  c.gpu_faster = c.renders > 0 ? c.gpu_s < c.cpu_s : m.gpu_cells_per_second > cpu_rate;
  c.backend = c.gpu_faster && gpu_usable ? "cuda" : "cpu_threads";
  c.why = c.renders > 0 ? workload_note(c, m, no_gpu) : rates_note(c, m, no_gpu);
  return c;
}

int auto_cores(const BackendOptions &options) {
  return options.threads > 0 ? options.threads : hardware_threads();
}

AutoChoice choose_auto(const ScanBatch *scans, const MapperParams &params, const BackendOptions &options) {
  const int renders = scans != nullptr ? options.expected_renders : 0;
  const double cells = scans != nullptr && renders > 0 ? estimated_cell_updates(*scans, params) : 0;
  const int cores = auto_cores(options);
  const AutoChoice if_usable = choose_auto(cells, cores, renders, true);
  // Asking whether a GPU is usable starts its CUDA context: the very start-up
  // the rule weighs. So it is asked when the rule takes the GPU, and
  // otherwise only where the answer is known to be no at no cost (then the
  // note leaves out the GPU's time); else the note gives the GPU's time as
  // the rule saw it.
  if (!if_usable.gpu_faster && !no_gpu_at_no_cost()) return if_usable;
  std::string why;
  const bool usable = gpu_usable(options.cuda_device, &why);
  return choose_auto(cells, cores, renders, usable, why);
}

}  // namespace vasco
