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
  // The same on a grid just reset, which the backend writes itself: every
  // cell of `cells` outside `stale` is unknown, those inside it hold an
  // earlier render's values. It leaves the map of scans [first, last) in
  // every cell and returns the box outside which its cells are unknown. A
  // reset grid is filled once this way, not once by the reset and again by
  // the render (a large site's re-render: DESIGN, the CPU backends). By
  // default: the stale box filled with unknown, then apply_to.
  virtual Box apply_to_reset(const ScanBatch &scans, size_t first, size_t last, const MapperParams &params,
                             const GridGeometry &geo, const Box &stale, float *cells, MapStats *stats);

  // Fills the cells of `box` in a grid of `geo` with `value`.
  static void fill_box(float *cells, const GridGeometry &geo, const Box &box, float value);

 private:
  // The reset that reset() left to the next apply (or read), and the box
  // outside which the grid's cells are unknown already.
  void complete_reset();

  std::string name_;
  bool exact_;
  const double scratch_bytes_per_cell_;
  GridGeometry geo_;
  MapperParams params_;
  std::vector<float> cells_;
  bool reset_pending_ = false;
  Box written_;
};

// The CPU backends, each in its own source file.
std::unique_ptr<HostGridRenderer> make_cpu_double_renderer();
std::unique_ptr<HostGridRenderer> make_cpu_float_renderer();
std::unique_ptr<HostGridRenderer> make_cpu_threads_renderer(int threads);

}  // namespace vasco

#endif  // VASCO_GPU_SRC_HOST_RENDERER_H
