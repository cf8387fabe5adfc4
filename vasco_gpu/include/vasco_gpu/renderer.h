// renderer.h — the one interface of a mapping backend: a renderer owns one
// evidence grid (in host or device memory) and applies scans to it. Every
// backend (cpu_double, cpu_threads, cpu_float, cuda) is a Renderer; the
// Mapper session, log2map, the C APIs, the tests and the benchmarks all
// drive renderers through it.
#ifndef VASCO_GPU_RENDERER_H
#define VASCO_GPU_RENDERER_H

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "carmen_compat/occupancy_value.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/grid.h"
#include "vasco_gpu/params.h"
#include "vasco_gpu/scan_batch.h"

namespace vasco {

// A laser pose in the world frame.
struct Pose {
  double x = 0, y = 0, theta = 0;
};

// A rectangle of cells of the full-resolution grid: [x0, x0 + width) x [y0, y0 + height).
struct GridWindow {
  int x0 = 0, y0 = 0, width = 0, height = 0;
};

// Where finish_occupancy writes a finished map of `cells` cells as
// OccupancyGrid data: a buffer of that many bytes, valid until the call
// returns.
using OccupancyOut = std::function<int8_t *(size_t cells)>;

// What a renderer is, for its users: whether its grid is CARMEN's bytes
// (cpu_double's), whether the grid lives in device memory (so the host
// memory budget does not count it), and what it keeps per cell of its grid
// at most, in host memory (what the Mapper's budget counts, with the finish
// and the scans: Mapper::memory_need) and in device memory (what the GPU's
// free memory must hold; checked when the grid is allocated).
struct RendererTraits {
  bool exact = false;
  bool grid_on_device = false;
  double host_bytes_per_cell = 4;    // a host grid's floats, and any per-cell scratch
  double device_bytes_per_cell = 0;  // the grid and per-cell scratch on the device (the finish adds 8 / ds^2)
};

// Owns one evidence grid and applies scans to it with one backend.
class Renderer {
 public:
  virtual ~Renderer() = default;
  virtual std::string name() const = 0;
  // Starts over: every cell of a grid of `geo` unknown.
  virtual void reset(const GridGeometry &geo, const MapperParams &params) = 0;
  // Applies scans [first, last) of `scans` (poses included) after those
  // applied since the reset; scan 0 fixes CARMEN's start pose.
  virtual void apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) = 0;
  // CARMEN's finish of the current grid (DESIGN §2 step 7).
  virtual FinishedMap finish(int downsample, int border) = 0;
  // The same finish as nav_msgs/OccupancyGrid data by `values`
  // (carmen_compat/occupancy_grid.h: row-major from the lower-left cell),
  // written into out(n) once the finished map's n cells are known; returns
  // the finished map with its cells left empty. By default finish, then the
  // host's conversion (occupancy_of); the CUDA renderers convert on the
  // device and send one byte a cell instead of a float.
  virtual FinishedMap finish_occupancy(int downsample, int border, const carmen::OccupancyValues &values,
                                       const OccupancyOut &out);
  // finish and finish_occupancy of a window of the grid (inside it), as if
  // the window were the whole grid of cells `resolution` metres: a Mapper
  // whose grid grew past its frame finishes the frame's cells. By default
  // the window is read a strip of columns at a time and finished on the
  // host; the CUDA renderers finish it on the device, where a live map's
  // publication would otherwise bring the whole window's floats across.
  virtual FinishedMap finish_window(const GridWindow &window, double resolution, int downsample, int border);
  virtual FinishedMap finish_occupancy_window(const GridWindow &window, double resolution, int downsample,
                                              int border, const carmen::OccupancyValues &values,
                                              const OccupancyOut &out);
  // A window of the full-resolution grid, x-major (cells[x * height + y]);
  // the window must lie inside the grid.
  virtual std::vector<float> read(const GridWindow &window) = 0;
  // Throws, changing nothing, when a grid cannot hold `beams` beams applied
  // since its reset (CUDA float mode's fixed-point range); the Mapper asks
  // before it stores scans or poses. By default every count fits.
  virtual void check_capacity(uint64_t beams) const { (void)beams; }
  // The session's scans were replaced by others (Mapper::start_over): a
  // renderer that keeps a copy of the scans applied so far (CUDA float
  // mode's device ranges, sent once and reused) must drop it. The grid is
  // reset before the next apply, as always.
  virtual void forget_scans() {}
  // What the renderer is: the Mapper asks this instead of reading its name.
  virtual RendererTraits traits() const = 0;
};

// The renderer of a backend name or alias (backend_registry(): cpu_double,
// cpu_threads, cpu_float, cuda, auto; cuda_exact and cuda_float set the CUDA
// mode). Throws Error(Usage) for an unknown name and Error(NoGpu) for cuda
// when this build has no CUDA backend or no GPU is usable (the message says
// why); auto falls back to cpu_threads.
std::unique_ptr<Renderer> make_renderer(const std::string &backend, const BackendOptions &options = {});

// A finished map's cells as OccupancyGrid data by `values`, into out(n):
// the map returned with its cells dropped (finish_occupancy's host half).
FinishedMap occupancy_of(FinishedMap map, const carmen::OccupancyValues &values, const OccupancyOut &out);

// Every scan of `scans` on a fresh grid of `geo`: reset, apply, and the whole
// full-resolution grid read back (x-major). What a one-shot map is.
std::vector<float> render_grid(Renderer &renderer, const ScanBatch &scans, const MapperParams &params,
                               const GridGeometry &geo, MapStats *stats = nullptr);

}  // namespace vasco

#endif  // VASCO_GPU_RENDERER_H
