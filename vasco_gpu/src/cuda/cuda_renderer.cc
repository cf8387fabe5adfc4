// The CUDA renderers' shared part: the device and stream, reset and apply's
// guard of the grid's state, and CARMEN's finish and the window read on the
// device (only the finished map or the window comes back, into pinned
// memory). Every call ends with the stream idle, so staging is free at the
// start of the next.
#include "cuda_renderer.h"

#include <algorithm>
#include <cstring>

namespace vasco {

using cuda_host::grow_to;

CudaRenderer::CudaRenderer(const BackendOptions &options, cudaStream_t stream, bool exact)
    : options_(options), exact_(exact) {
  select_device();
  if (stream == nullptr) {
    own_stream_ = std::make_unique<cuda::Stream>();
    stream = own_stream_->get();
  }
  stream_ = stream;
  events_ = std::make_unique<PhaseEvents>();
}

CudaRenderer::~CudaRenderer() = default;

void CudaRenderer::select_device() const { VG_CUDA_CHECK(cudaSetDevice(options_.cuda_device)); }

void CudaRenderer::require_grid(const char *call) const {
  if (state_ == GridState::Valid) return;
  throw Error(ErrorCode::State, std::string(call) + " on " + name() +
                                    (state_ == GridState::None
                                         ? ": no grid yet (reset first)"
                                         : ": the grid was lost by a failed call; reset and apply the scans again"));
}

// Check and allocate (the mode's reserve_grid), then commit: a refusal
// changes neither the frame nor the grid.
void CudaRenderer::reset(const GridGeometry &geo, const MapperParams &params) {
  reset_band(geo, params, ColumnBand{0, geo.size_x});
}

void CudaRenderer::reset_band(const GridGeometry &geo, const MapperParams &params, ColumnBand band) {
  const bool whole = band.x0 == 0 && band.width == geo.size_x;
  if (band.x0 < 0 || band.width < 0 || band.width > geo.size_x - band.x0 ||
      (!whole && geo.size_x > kMaxBandedSide))
    throw Error(ErrorCode::Internal, "a band of columns [" + std::to_string(band.x0) + ", +" +
                                         std::to_string(band.width) + ") of a grid " + std::to_string(geo.size_x) +
                                         " cells wide (a bug)");
  select_device();
  // The frame's window copy (a grown grid's finish, a whole read) is scratch
  // of the frame's size: freed before a new grid is fitted into the device's
  // memory, so that it never refuses a grid that fits without it.
  window_.reset();
  GridGeometry grid = geo;
  grid.size_x = band.width;
  reserve_grid(grid);
  geo_ = geo;
  grid_geo_ = grid;
  band_x0_ = band.x0;
  params_ = params;
  state_ = GridState::Lost;  // until it is cleared
  blocks_ds_ = 0;
  clear_grid();
  state_ = GridState::Valid;
}

void CudaRenderer::apply(const ScanBatch &scans, size_t first, size_t last, MapStats *stats) {
  require_grid("apply");
  select_device();
  last = std::min(last, scans.num_scans());
  first = std::min(first, last);
  MapStats st;
  st.scans = last - first;
  if (last > first) apply_scans(scans, first, last, &st);
  if (stats != nullptr) *stats = st;
}

void CudaRenderer::PhaseEvents::add_times(MapStats *st) const {
  st->upload_s += uploaded.since(start) / 1e3;
  st->map_s += mapped.since(uploaded) / 1e3;
}

// n floats of device memory into pinned staging (the stream idle after).
cuda::PinnedBuffer<float> &CudaRenderer::download(const float *device, size_t n) {
  grow_to(staging_out_, std::max<size_t>(n, 1));
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_out_.get(), device, n * sizeof(float), cudaMemcpyDeviceToHost, stream_));
  VG_CUDA_CHECK(cudaStreamSynchronize(stream_));
  return staging_out_;
}

// finish_math.h's finish: the block means and the known box on the device,
// the crop's bounds on the host, the crop on the device.
FinishedMap CudaRenderer::finish(int downsample, int border) {
  finish::Crop crop;
  FinishedMap m = finish_frame(downsample, border, &crop);
  m.cells = read_blocks(crop);
  return m;
}

// The block means on the device and the finished map's frame (its cells not
// filled), `crop` its window of the blocks.
FinishedMap CudaRenderer::finish_frame(int downsample, int border, finish::Crop *crop) {
  finish::check_arguments(downsample, border);
  require_grid("finish");
  const finish::KnownBox known = finish_blocks(downsample);
  const finish::Blocks blocks = finish::blocks_of(grid_geo_.size_x, grid_geo_.size_y, downsample);
  *crop = finish::crop_of(known, blocks, border);
  return finish::finished_frame(*crop, grid_geo_.resolution, downsample);
}

FinishedMap CudaRenderer::finish_occupancy(int downsample, int border, const carmen::OccupancyValues &values,
                                           const OccupancyOut &out) {
  finish::Crop crop;
  FinishedMap m = finish_frame(downsample, border, &crop);
  download_occupancy(finish::blocks_of(grid_geo_.size_x, grid_geo_.size_y, downsample), crop, values, out);
  return m;
}

finish::KnownBox CudaRenderer::finish_blocks(int downsample) {
  require_grid("finish");
  select_device();
  const finish::KnownBox known = block_means(cells(), grid_geo_.size_x, grid_geo_.size_y, downsample);
  blocks_ds_ = downsample;
  return known;
}

finish::KnownBox CudaRenderer::block_means(cuda::GridCells grid, int size_x, int size_y, int downsample) {
  const finish::Blocks blocks = finish::blocks_of(size_x, size_y, downsample);
  blocks_ds_ = 0;  // until the caller says whose means they are (a failed growth empties blocks_)
  cuda_host::grow_to_checked(blocks_, std::max<size_t>(static_cast<size_t>(blocks.count()), 1),
                             "the finish's block means");
  grow_to(known_, 1);
  grow_to(staging_known_, 1);
  VG_CUDA_CHECK(cudaStreamSynchronize(stream_));
  staging_known_[0] = finish::KnownBox{};
  VG_CUDA_CHECK(cudaMemcpyAsync(known_.get(), staging_known_.get(), sizeof(finish::KnownBox),
                                cudaMemcpyHostToDevice, stream_));
  cuda::launch_finish_blocks(grid, size_x, size_y, downsample, blocks_.get(), known_.get(), stream_);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_known_.get(), known_.get(), sizeof(finish::KnownBox),
                                cudaMemcpyDeviceToHost, stream_));
  VG_CUDA_CHECK(cudaStreamSynchronize(stream_));
  return staging_known_[0];
}

std::vector<float> CudaRenderer::read_blocks(const finish::Crop &crop) {
  require_grid("finish");
  if (blocks_ds_ < 1) throw Error(ErrorCode::Internal, "read_blocks before finish_blocks (a bug)");
  select_device();
  return download_crop(finish::blocks_of(grid_geo_.size_x, grid_geo_.size_y, blocks_ds_), crop);
}

std::vector<float> CudaRenderer::download_crop(const finish::Blocks &blocks, const finish::Crop &crop) {
  const size_t n = static_cast<size_t>(crop.count());
  cuda_host::grow_to_checked(finished_, std::max<size_t>(n, 1), "the finished map");
  cuda::launch_crop(blocks_.get(), blocks, crop, finished_.get(), stream_);
  const cuda::PinnedBuffer<float> &out = download(finished_.get(), n);
  return std::vector<float>(out.get(), out.get() + n);
}

void CudaRenderer::download_occupancy(const finish::Blocks &blocks, const finish::Crop &crop,
                                      const carmen::OccupancyValues &values, const OccupancyOut &out) {
  const size_t n = static_cast<size_t>(crop.count());
  cuda_host::grow_to_checked(occupancy_, std::max<size_t>(n, 1), "the finished map's OccupancyGrid data");
  grow_to(staging_occupancy_, std::max<size_t>(n, 1));
  cuda::launch_occupancy_crop(blocks_.get(), blocks, crop, values, occupancy_.get(), stream_);
  VG_CUDA_CHECK(cudaMemcpyAsync(staging_occupancy_.get(), occupancy_.get(), n, cudaMemcpyDeviceToHost, stream_));
  VG_CUDA_CHECK(cudaStreamSynchronize(stream_));
  int8_t *data = out(n);
  if (n > 0) std::memcpy(data, staging_occupancy_.get(), n);
}

// The window's probabilities are the floats read() gives (launch_read_window:
// the expressions finish uses), so the block means of the copy are the host
// path's, bit for bit (MapperCuda tests of a grown grid). Throws
// OutOfMemory, before anything but scratch changed, where the device cannot
// hold the copy.
FinishedMap CudaRenderer::window_frame(const GridWindow &w, double resolution, int downsample, int border,
                                       finish::Crop *crop) {
  finish::check_arguments(downsample, border);
  require_grid("finish");
  if (w.x0 < 0 || w.y0 < 0 || w.width < 1 || w.height < 1 || w.width > grid_geo_.size_x - w.x0 ||
      w.height > grid_geo_.size_y - w.y0)
    throw Error(ErrorCode::Internal, "a finish window outside the grid (a bug)");
  select_device();
  const size_t n = static_cast<size_t>(w.width) * static_cast<size_t>(w.height);
  cuda_host::grow_to_checked(window_, n, "the frame's window of the grid");
  VG_CUDA_CHECK(cudaStreamSynchronize(stream_));
  cuda::launch_read_window(cells(), grid_geo_.size_y, w.x0, w.y0, w.width, w.height, window_.get(), stream_);
  cuda::GridCells copy;
  copy.probs = window_.get();
  const finish::KnownBox known = block_means(copy, w.width, w.height, downsample);
  *crop = finish::crop_of(known, finish::blocks_of(w.width, w.height, downsample), border);
  return finish::finished_frame(*crop, resolution, downsample);
}

// A device that cannot hold the window's copy or the finish's scratch (its
// memory taken by the grid, or by another process): the host's way, as
// before the device finished windows. The failed allocation's error is
// cleared first, or the next launch check would report it.
template <class DeviceWay, class HostWay>
FinishedMap CudaRenderer::on_device_else(DeviceWay device_way, HostWay host_way) {
  try {
    return device_way();
  } catch (const Error &e) {
    if (e.code() != ErrorCode::OutOfMemory) throw;
  }
  (void)cudaGetLastError();
  return host_way();
}

FinishedMap CudaRenderer::finish_window(const GridWindow &window, double resolution, int downsample, int border) {
  return on_device_else(
      [&] {
        finish::Crop crop;
        FinishedMap m = window_frame(window, resolution, downsample, border, &crop);
        m.cells = download_crop(finish::blocks_of(window.width, window.height, downsample), crop);
        return m;
      },
      [&] { return Renderer::finish_window(window, resolution, downsample, border); });
}

// out(n) is called once, after every allocation of the device's way: a
// fallback never follows it.
FinishedMap CudaRenderer::finish_occupancy_window(const GridWindow &window, double resolution, int downsample,
                                                  int border, const carmen::OccupancyValues &values,
                                                  const OccupancyOut &out) {
  return on_device_else(
      [&] {
        finish::Crop crop;
        FinishedMap m = window_frame(window, resolution, downsample, border, &crop);
        download_occupancy(finish::blocks_of(window.width, window.height, downsample), crop, values, out);
        return m;
      },
      [&] { return Renderer::finish_occupancy_window(window, resolution, downsample, border, values, out); });
}

std::vector<float> CudaRenderer::read(const GridWindow &w) {
  require_grid("read");
  select_device();
  const size_t n = static_cast<size_t>(w.width) * static_cast<size_t>(w.height);
  cuda_host::grow_to_checked(window_, std::max<size_t>(n, 1), "the window read");
  VG_CUDA_CHECK(cudaStreamSynchronize(stream_));
  cuda::launch_read_window(cells(), grid_geo_.size_y, w.x0, w.y0, w.width, w.height, window_.get(), stream_);
  const cuda::PinnedBuffer<float> &out = download(window_.get(), n);
  return std::vector<float>(out.get(), out.get() + n);
}

}  // namespace vasco
