// backend.h — the mapping backends: their options, their statistics, and the
// one registry of their names (backend_registry()) that make_renderer
// (renderer.h), the session APIs, egrid.h and the tools' --backend all read.
#ifndef VASCO_GPU_BACKEND_H
#define VASCO_GPU_BACKEND_H

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

// Counts and phase times of one mapping run.
struct MapStats {
  uint64_t scans = 0;
  uint64_t beams_used = 0;     // range < 50 m: traced
  uint64_t beams_skipped = 0;  // range >= 50 m, NaN or +inf: skipped entirely
  uint64_t cell_updates = 0;   // odds updates applied
  double prep_s = 0;           // host work before the upload (GPU backends: placing beams)
  double upload_s = 0;         // host -> device (GPU backends)
  double map_s = 0;            // the update itself (kernels only, for GPU backends)
  double download_s = 0;       // device -> host
};

enum class CudaMode { Float, Exact };

// The host-memory budget of a mapping session by default: 2 GiB, which a
// laptop has to spare. There is no cap on a grid's cells: the budget is what
// bounds a host grid (4.5 bytes a cell on cpu_double and cpu_threads at
// vasco_downsample 4, 8.5 on cpu_float: a 546 m or a 397 m square at 2.5
// cm), and a grid of 10^9 cells (two scans 400 m apart) is refused before
// anything is allocated, naming the need and how to raise the budget. It
// stays 2 GiB rather than a share of the machine's memory because what it
// catches most is a bad pose (a scan kilometres off), where a refusal in
// well under a second beats minutes of paging; a large site is mapped by
// asking for it (log2map --max-memory, max_memory_bytes). A GPU's grid is
// bounded by the device's free memory instead; the host then holds only
// the finished map (0.5 bytes a cell at downsample 4).
constexpr uint64_t kDefaultMaxMemoryBytes = uint64_t(2) << 30;

// The most threads a session's cpu_threads may use (BackendOptions::threads,
// log2map --threads, Python's threads): each keeps scratch for the life of
// the renderer, so a count far beyond any machine's cores is refused, not
// capped silently.
constexpr int kMaxThreads = 1024;

struct BackendOptions {
  CudaMode cuda_mode = CudaMode::Float;
  int threads = 0;   // cpu_threads: 0 = all cores, at most kMaxThreads
  int cuda_device = 0;
  // cuda: one render split across these devices, two or more (the grid's
  // columns in bands, one a device; a device may repeat). Bit-identical to
  // one device's render in both modes. Empty: one device, cuda_device.
  std::vector<int> split_devices;
  uint64_t max_memory_bytes = kDefaultMaxMemoryBytes;  // host memory a Mapper may use (0: no limit)
  // How the caller raises max_memory_bytes, as a refusal names it ("log2map
  // --max-memory MiB", "vasco_mapper_set_max_memory"); empty: not named.
  std::string budget_hint;
  // auto: the renders expected of the workload (backend_choice.h): 1, a
  // session's first insert mapped once (log2map's rule, decided at that
  // insert); more, a session that renders again; 0, a workload without end
  // (batches, live maps: decided when the session is made). At least 0.
  int expected_renders = 1;
};

class Renderer;

// Another name of a backend: one that also chooses its CUDA mode
// (cuda_exact, cuda_float), or one that leaves the mode as it is (gpu:
// sets_cuda_mode false, cuda_mode then unused).
struct BackendAlias {
  const char *name;
  CudaMode cuda_mode;
  bool sets_cuda_mode = true;
};

// Whether a backend's grid is CARMEN's bytes.
enum class Exactness { Exact, Float, ByCudaMode };

// One row of the registry: everything the APIs and the tools say about a backend.
struct BackendInfo {
  const char *name;                   // what make_renderer takes: cpu_double, ..., auto
  std::vector<BackendAlias> aliases;  // other names, some of which also set BackendOptions::cuda_mode
  Exactness exactness;
  bool grid_on_device;
  bool compiled;        // false: named but not in this build (cuda without nvcc)
  const char *summary;  // one line, for --backend's help and the docs
  // What a front end's options mean for it, so that none decides by name
  // (log2map warns of an option that does nothing, hands GPUs to a batch):
  bool uses_gpus;     // a CUDA device and mode matter (--device, --devices, --split-devices, --cuda-mode)
  bool uses_threads;  // BackendOptions::threads matters (--threads)
  bool chooses;       // picks another backend for each input (auto); the tools say which
  // Creates the renderer; throws Error(NoGpu) when the backend cannot run here.
  std::unique_ptr<Renderer> (*make)(const BackendOptions &options);
};

// Every backend, compiled in or not, in the order the help lists them.
const std::vector<BackendInfo> &backend_registry();

// The row of a backend name or alias; null when there is none.
const BackendInfo *find_backend(const std::string &name_or_alias);

// The names make_renderer accepts in this build, "auto" included (it always
// runs: cuda or cpu_threads by backend_choice.h's rule).
std::vector<std::string> compiled_backends();

// The session APIs' names (C API, egrid.h, Python, log2map's --backend): a
// name or an alias. Returns the registry's name; an alias that sets a mode
// sets options->cuda_mode. Throws Error(Usage) for a name that is neither,
// listing the known names and, for a near miss, "did you mean 'cpu_double'?".
std::string resolve_backend_name(const std::string &name, BackendOptions *options);

// The name of `known` closest to `name` by edit distance (letters inserted,
// deleted, replaced or two neighbours swapped; case ignored) when it is
// close enough to be a typo of it: at most one edit for names of up to 7
// letters, two up to 11, three beyond. Empty when none is; the first of
// equally close ones. For "did you mean" in messages: the backend names
// here, log2map's option names.
std::string closest_name(const std::string &name, const std::vector<std::string> &known);

// Every name and alias resolve_backend_name accepts, compiled in or not. A
// session reports its backend (Renderer::name()) as one of them: a CPU name,
// cuda_float or cuda_exact.
std::vector<std::string> backend_names();

// The help text of a --backend option: one "name: summary" line per
// compiled backend.
std::string backend_help();

// How many CUDA devices this process sees (CUDA_VISIBLE_DEVICES applies): 0
// without a driver, a device or a CUDA build. Usable or not is cuda_usable's.
int cuda_device_count();

// Whether the cuda backend can run on `device` (false in a build without
// CUDA); `why` (optional) says why not.
bool gpu_usable(int device, std::string *why = nullptr);

}  // namespace vasco

#endif  // VASCO_GPU_BACKEND_H
