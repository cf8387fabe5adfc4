// host_renderer.h — the base of every CPU backend: a Renderer whose grid is
// a vector of cells in host memory, which the backend updates in place.
// Internal to the library (the backends' sources and the registry).
#ifndef VASCO_GPU_SRC_HOST_RENDERER_H
#define VASCO_GPU_SRC_HOST_RENDERER_H

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "beam_updates.h"
#include "vasco_gpu/backend.h"
#include "vasco_gpu/renderer.h"

namespace vasco {

class HostGridRenderer : public Renderer {
 public:
  // `scratch_bytes_per_cell`: what the backend keeps per cell of the grid
  // besides the grid's own 4-byte floats (cpu_float's sums), for the
  // session's memory budget.
  HostGridRenderer(std::string name, bool exact, double scratch_bytes_per_cell = 0)
      : name_(std::move(name)), exact_(exact), scratch_bytes_per_cell_(scratch_bytes_per_cell) {}

  std::string name() const override { return name_; }
  RendererTraits traits() const override { return {exact_, false, sizeof(float) + scratch_bytes_per_cell_, 0}; }

  void reset(const GridGeometry &geo, const MapperParams &params) override;
  void apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) override;
  FinishedMap finish(int downsample, int border) override;
  std::vector<float> read(const GridWindow &window) override;

  // The backend's update: applies scans [first, last) of `scans` to `cells`
  // (x-major, a grid of `geo`), which hold the result of scans [0, first);
  // scan 0 fixes CARMEN's start pose.
  virtual void apply_to(const ScanBatch &scans, size_t first, size_t last, const MapperParams &params,
                        const GridGeometry &geo, float *cells, MapStats *stats) = 0;

  using Box = beam_updates::Box;
  // Cells [lo, hi) of the buffer (x-major): every cell outside is unknown.
  struct CellRange {
    size_t lo = 0, hi = 0;
  };
  // The same on a grid just reset, which the backend writes itself: the
  // cells in `stale` may hold an earlier render's values (in an earlier
  // shape of the grid), every other cell is unknown. It leaves the map of
  // scans [first, last) in every cell of the grid and returns the box
  // outside which its cells are unknown. A reset grid is filled once this
  // way, not once by the reset and again by the render (a large site's
  // re-render: docs/performance.md). By default: the stale cells made
  // unknown, then apply_to.
  virtual Box apply_to_reset(const ScanBatch &scans, size_t first, size_t last, const MapperParams &params,
                             const GridGeometry &geo, const CellRange &stale, float *cells, MapStats *stats);

  // The cells of `box` in a grid of `geo` set to `value`.
  static void fill_box(float *cells, const GridGeometry &geo, const Box &box, float value);
  // The cells of `stale` outside `box` (in a grid of `geo`) made unknown.
  static void clear_outside(float *cells, const GridGeometry &geo, const CellRange &stale, const Box &box);

 private:
  // The reset that reset() left to the next apply (or read).
  void complete_reset();

  std::string name_;
  bool exact_;
  const double scratch_bytes_per_cell_;
  GridGeometry geo_;
  MapperParams params_;
  std::vector<float> cells_;  // the grid: its first geo_.num_cells(); kept at its largest size
  bool reset_pending_ = false;
  CellRange written_;  // the cells an apply may have written since the buffer was all unknown
};

// The CPU backends, each in its own source file.
std::unique_ptr<HostGridRenderer> make_cpu_double_renderer();
std::unique_ptr<HostGridRenderer> make_cpu_float_renderer();
std::unique_ptr<HostGridRenderer> make_cpu_threads_renderer(int threads);

}  // namespace vasco

#endif  // VASCO_GPU_SRC_HOST_RENDERER_H
