// cuda_renderer.h — what the CUDA renderers of float and exact mode share
// (private to the library: make_cuda_renderer in cuda_backend.h creates
// one): the device, the stream (the caller's, or one of its own), the phase
// events, the frame and parameters of the last reset, the band of the
// frame's columns the grid holds (all of them, or one GPU's share of a split
// render: split_renderer.h), CARMEN's finish and the window read on the
// device, and the grid's state.
//
// Every call is strongly exception-safe where the device allows it: a mode
// checks (GPU memory, fixed-point range) and allocates before it changes
// anything, so a refused reset or apply leaves the renderer as it was. A
// failure after the grid began to change (a later launch of a long exact
// apply, a CUDA error, an allocation refused after check_fits passed) leaves
// the grid lost: apply, finish and read then throw ErrorCode::State until a
// reset succeeds.
#ifndef VASCO_GPU_SRC_CUDA_RENDERER_H
#define VASCO_GPU_SRC_CUDA_RENDERER_H

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "cuda_check.h"
#include "cuda_host_support.h"
#include "egrid_kernels.h"
#include "vasco_gpu/cuda_backend.h"
#include "vasco_gpu/renderer.h"

namespace vasco {

// The columns [x0, x0 + width) of a frame: what a renderer's grid holds.
struct ColumnBand {
  int x0 = 0, width = 0;
};

// The widest frame a render may be split in bands of: 2^30 columns. A band
// walks every beam in the frame's cell numbers (CARMEN's walk compares end
// points, so a moved line is not the same walk when a move wraps one past
// INT_MIN) and keeps the cells of its columns; the kernels subtract the
// band's first column from a cell's x, which this keeps well inside an int
// for every cell a closed-form line visits.
constexpr int kMaxBandedSide = 1 << 30;

class CudaRenderer : public Renderer {
 public:
  ~CudaRenderer() override;
  RendererTraits traits() const override { return {exact_, true, 0, device_bytes_per_cell()}; }
  void reset(const GridGeometry &geo, const MapperParams &params) final;
  // reset, for a grid that holds only the columns of `band` of the frame
  // `geo`: the beams are placed in `geo` (the cells the whole grid's render
  // would update), and only the band's cells are kept and updated, with the
  // same values. finish and read see the band as a grid of band.width x
  // geo.size_y cells. A band must lie inside the frame, and a frame split in
  // bands must be at most kMaxBandedSide columns wide (split_renderer.h says
  // why).
  void reset_band(const GridGeometry &geo, const MapperParams &params, ColumnBand band);
  // The device the renderer's grid is on.
  int device() const { return options_.cuda_device; }
  // finish in two steps, for a split render's bands: the block means at
  // `downsample` into device scratch, returning the known blocks' box (in
  // this grid's blocks); then a window of those blocks (crop: its first block
  // column and row, its size) to the host, x-major. finish is the two.
  finish::KnownBox finish_blocks(int downsample);
  std::vector<float> read_blocks(const finish::Crop &crop);
  void apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) final;
  FinishedMap finish(int downsample, int border) final;
  // finish's crop converted on the device (launch_occupancy_crop): a byte a
  // cell comes back instead of a float.
  FinishedMap finish_occupancy(int downsample, int border, const carmen::OccupancyValues &values,
                               const OccupancyOut &out) final;
  // The window copied on the device as probabilities (the floats read
  // gives), then finished there as a grid of its own: only the finished map
  // crosses the bus. Where the device cannot hold the copy, the host's way.
  FinishedMap finish_window(const GridWindow &window, double resolution, int downsample, int border) final;
  FinishedMap finish_occupancy_window(const GridWindow &window, double resolution, int downsample, int border,
                                      const carmen::OccupancyValues &values, const OccupancyOut &out) final;
  std::vector<float> read(const GridWindow &window) final;

 protected:
  // `stream`: the caller's (used, never destroyed), or null for one of the
  // renderer's own. It must belong to options.cuda_device.
  CudaRenderer(const BackendOptions &options, cudaStream_t stream, bool exact);

  // The mode's part of reset, before anything changes: refuses (check_fits)
  // or allocates what a grid of `geo` needs. Growing the grid drops its
  // contents: do it with grow_grid.
  virtual void reserve_grid(const GridGeometry &geo) = 0;
  // After the reset is committed (geo() and params() are the new ones):
  // every cell unknown.
  virtual void clear_grid() = 0;
  // Scans [first, last), first < last, onto the grid. Checks and allocates
  // first; brackets the launches that change the grid with begin_update()
  // and end_update().
  virtual void apply_scans(const ScanBatch &scans, size_t first, size_t last, MapStats *st) = 0;
  // The grid as finish and read see it.
  virtual cuda::GridCells cells() const = 0;
  // Device memory the mode keeps per cell of its grid at most (the grid and
  // its per-cell scratch; docs/performance.md, "Large sites: past 2^30 cells").
  virtual double device_bytes_per_cell() const = 0;

  // Grows the grid to `cells` (dropping its contents), refused first by
  // check_fits when the growth and `extra_bytes` (the mode's per-cell scratch
  // allocated with it) would not fit in the device's free memory: the
  // refusal names the grid, the bytes needed and the bytes free.
  template <class T>
  void grow_grid(cuda::DeviceBuffer<T> &grid, const GridGeometry &geo, size_t extra_bytes = 0) {
    const size_t cells = static_cast<size_t>(geo.num_cells());
    const size_t growth = cuda_host::growth_bytes(grid, cells);
    if (growth + extra_bytes == 0) return;
    const double per_cell = sizeof(T) + static_cast<double>(extra_bytes) / std::max(1.0, static_cast<double>(cells));
    cuda_host::check_fits(growth + extra_bytes, cuda_host::grid_description(geo, per_cell).c_str());
    if (cells <= grid.size()) return;
    state_ = GridState::Lost;  // the reallocation drops the old grid
    cuda_host::grow_to(grid, cells);
  }
  void begin_update() { state_ = GridState::Lost; }  // until end_update: a throw leaves it lost
  void end_update() { state_ = GridState::Valid; }

  void select_device() const;
  cudaStream_t stream() const { return stream_; }
  // The frame the beams are placed in (the whole grid's).
  const GridGeometry &geo() const { return geo_; }
  // The cells the grid holds: the band's columns of the frame, band_x0()
  // its first.
  const GridGeometry &grid_geo() const { return grid_geo_; }
  int band_x0() const { return band_x0_; }
  const MapperParams &params() const { return params_; }

  // The phase times of an apply: start, uploaded, mapped.
  struct PhaseEvents {
    cuda::Event start, uploaded, mapped;
    void add_times(MapStats *st) const;
  };
  PhaseEvents &events() { return *events_; }

 private:
  enum class GridState { None, Valid, Lost };
  void require_grid(const char *call) const;
  cuda::PinnedBuffer<float> &download(const float *device, size_t n);
  FinishedMap finish_frame(int downsample, int border, finish::Crop *crop);
  // The block means of `grid` (size_x x size_y cells) into blocks_, and the
  // known blocks' box.
  finish::KnownBox block_means(cuda::GridCells grid, int size_x, int size_y, int downsample);
  // finish_frame of a window, copied into window_ first.
  FinishedMap window_frame(const GridWindow &window, double resolution, int downsample, int border,
                           finish::Crop *crop);
  // device_way(), or host_way() where it ran out of device memory.
  template <class DeviceWay, class HostWay>
  FinishedMap on_device_else(DeviceWay device_way, HostWay host_way);
  // The crop of blocks_ (the block grid `blocks`): as floats, and as
  // OccupancyGrid data into out.
  std::vector<float> download_crop(const finish::Blocks &blocks, const finish::Crop &crop);
  void download_occupancy(const finish::Blocks &blocks, const finish::Crop &crop,
                          const carmen::OccupancyValues &values, const OccupancyOut &out);

  BackendOptions options_;
  bool exact_;
  std::unique_ptr<cuda::Stream> own_stream_;  // null when the caller gave one
  cudaStream_t stream_ = nullptr;
  std::unique_ptr<PhaseEvents> events_;
  GridGeometry geo_, grid_geo_;
  int band_x0_ = 0;
  MapperParams params_;
  GridState state_ = GridState::None;
  // Finish and read.
  cuda::DeviceBuffer<float> blocks_, finished_, window_;
  int blocks_ds_ = 0;  // the downsample blocks_ holds the means of (0: none since the reset)
  cuda::DeviceBuffer<finish::KnownBox> known_;
  cuda::PinnedBuffer<finish::KnownBox> staging_known_;
  cuda::PinnedBuffer<float> staging_out_;
  cuda::DeviceBuffer<int8_t> occupancy_;
  cuda::PinnedBuffer<int8_t> staging_occupancy_;
};

}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_RENDERER_H
