// backend.h — the interface every mapping backend implements, and the
// factory that picks one by name.
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
// laptop has to spare (a 580 m square at 2.5 cm cells); a grid of 10^9 cells
// (two scans 400 m apart) does not fit it and is refused before anything is
// allocated.
constexpr uint64_t kDefaultMaxMemoryBytes = uint64_t(2) << 30;

struct BackendOptions {
  CudaMode cuda_mode = CudaMode::Float;
  int threads = 0;   // cpu_threads: 0 = all cores
  int cuda_device = 0;
  uint64_t max_memory_bytes = kDefaultMaxMemoryBytes;  // host memory a Mapper may use (0: no limit)
};

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  // Applies scans [first, last) of `batch`, in order, to `cells` (x-major,
  // cells[x * size_y + y], a grid of geometry `geo`), which holds the result
  // of scans [0, first): all unknown (-1) when first == 0. Scan 0 of the
  // batch fixes CARMEN's start pose whatever `first` is, so for the exact
  // backends applying 0..k in several calls gives the bytes of one call.
  virtual void apply(const ScanBatch &batch, size_t first, size_t last, const MapperParams &params,
                     const GridGeometry &geo, float *cells, MapStats *stats) = 0;
  // Applies every scan of `batch` to a fresh evidence grid of geometry `geo`
  // (all cells unknown) and returns it.
  virtual std::vector<float> map(const ScanBatch &batch, const MapperParams &params,
                                 const GridGeometry &geo, MapStats *stats) {
    std::vector<float> cells(geo.num_cells(), -1.0f);
    apply(batch, 0, batch.num_scans(), params, geo, cells.data(), stats);
    return cells;
  }
};

// Backend names accepted by make_backend: cpu_double, cpu_threads, cpu_float,
// cuda (if compiled in) and auto (cuda when a GPU is usable, else
// cpu_threads: the oracle's bytes on every core).
std::vector<std::string> compiled_backends();

// Creates a backend; throws std::invalid_argument for an unknown name and
// std::runtime_error for `cuda` without a usable GPU (the message says why).
std::unique_ptr<Backend> make_backend(const std::string &name, const BackendOptions &options = {});

// A backend name as the session APIs take it (C API, egrid.h): besides
// make_backend's names, "cuda_exact" and "cuda_float" (what Backend::name()
// reports) select the CUDA mode. Returns the make_backend name; sets
// options->cuda_mode for the two aliases.
std::string resolve_backend_name(const std::string &name, BackendOptions *options);

std::unique_ptr<Backend> make_cpu_double_backend();
std::unique_ptr<Backend> make_cpu_float_backend();

}  // namespace vasco

#endif  // VASCO_GPU_BACKEND_H
