// CARMEN's finish (DESIGN §2 step 7) on the device, so that a mapping
// session downloads only the finished map. One thread per ds x ds block
// runs finish_math.h's block_mean, the very code of the host's finish: the
// same float, bit for bit.
#include <algorithm>

#include "cuda_check.h"
#include "egrid_kernels.h"

namespace vasco {
namespace cuda {
namespace {

__device__ __forceinline__ float cell_prob(const GridCells &grid, size_t c) {
  return grid.sums ? prob_of_fixed(grid.logodds_prior, grid.sums[c]) : grid.probs[c];
}

// finish::block_mean's view of the grid.
struct CellProb {
  GridCells grid;
  __device__ float operator()(int64_t c) const { return cell_prob(grid, static_cast<size_t>(c)); }
};

// Each kernel takes a thread per element in a grid-stride loop, in 64 bits:
// a grid may pass 2^31 cells, and a launch is capped at kMaxBlocks.
__device__ __forceinline__ size_t first_index() { return blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x; }
__device__ __forceinline__ size_t index_stride() { return static_cast<size_t>(gridDim.x) * blockDim.x; }

__global__ void finish_blocks_kernel(GridCells grid, int size_y, int ds, finish::Blocks blocks_grid, float *blocks,
                                     finish::KnownBox *known) {
  const size_t n = static_cast<size_t>(blocks_grid.count());
  for (size_t b = first_index(); b < n; b += index_stride()) {
    const int bx = static_cast<int>(b / blocks_grid.ny), by = static_cast<int>(b % blocks_grid.ny);
    const finish::BlockMean m = finish::block_mean(CellProb{grid}, size_y, ds, bx, by);
    if (m.known) {
      atomicMin(&known->min_x, bx);
      atomicMax(&known->max_x, bx);
      atomicMin(&known->min_y, by);
      atomicMax(&known->max_y, by);
    }
    blocks[b] = m.value;
  }
}

__global__ void crop_kernel(const float *blocks, finish::Blocks blocks_grid, finish::Crop crop, float *out) {
  const size_t n = static_cast<size_t>(crop.count());
  for (size_t c = first_index(); c < n; c += index_stride()) {
    const int x = static_cast<int>(c / crop.size_y), y = static_cast<int>(c % crop.size_y);
    out[c] = blocks[finish::cropped_block(crop, blocks_grid, x, y)];
  }
}

// One thread per byte of the data, in the rows' order: the writes coalesce,
// the reads of the x-major blocks are scattered (the L2 holds them: a
// finished map is a few MB at most in the cases the node publishes).
__global__ void occupancy_crop_kernel(const float *blocks, finish::Blocks blocks_grid, finish::Crop crop,
                                      carmen::OccupancyValues values, int8_t *out) {
  const size_t n = static_cast<size_t>(crop.count());
  for (size_t c = first_index(); c < n; c += index_stride()) {
    const int y = static_cast<int>(c / crop.size_x), x = static_cast<int>(c % crop.size_x);
    out[c] = carmen::occupancy_value(values, blocks[finish::cropped_block(crop, blocks_grid, x, y)]);
  }
}

__global__ void window_kernel(GridCells grid, int size_y, int x0, int y0, int width, int height, float *out) {
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  for (size_t c = first_index(); c < n; c += index_stride()) {
    const int x = static_cast<int>(c / height), y = static_cast<int>(c % height);
    out[c] = cell_prob(grid, static_cast<size_t>(egrid::cell_index(x0 + x, y0 + y, size_y)));
  }
}

// Blocks of 256 threads for n elements, at most 2^24 (the kernels loop).
constexpr size_t kMaxBlocks = size_t(1) << 24;
unsigned blocks_of(size_t n) { return static_cast<unsigned>(std::min((n + 255) / 256, kMaxBlocks)); }

}  // namespace

void launch_finish_blocks(GridCells grid, int size_x, int size_y, int ds, float *blocks, finish::KnownBox *known,
                          cudaStream_t stream) {
  const finish::Blocks blocks_grid = finish::blocks_of(size_x, size_y, ds);
  const size_t n = static_cast<size_t>(blocks_grid.count());
  if (n == 0) return;
  finish_blocks_kernel<<<blocks_of(n), 256, 0, stream>>>(grid, size_y, ds, blocks_grid, blocks, known);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_crop(const float *blocks, finish::Blocks blocks_grid, finish::Crop crop, float *out,
                 cudaStream_t stream) {
  const size_t n = static_cast<size_t>(crop.count());
  if (n == 0) return;
  crop_kernel<<<blocks_of(n), 256, 0, stream>>>(blocks, blocks_grid, crop, out);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_occupancy_crop(const float *blocks, finish::Blocks blocks_grid, finish::Crop crop,
                           carmen::OccupancyValues values, int8_t *out, cudaStream_t stream) {
  const size_t n = static_cast<size_t>(crop.count());
  if (n == 0) return;
  occupancy_crop_kernel<<<blocks_of(n), 256, 0, stream>>>(blocks, blocks_grid, crop, values, out);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_read_window(GridCells grid, int size_y, int x0, int y0, int width, int height, float *out,
                        cudaStream_t stream) {
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (n == 0) return;
  window_kernel<<<blocks_of(n), 256, 0, stream>>>(grid, size_y, x0, y0, width, height, out);
  VG_CUDA_CHECK_LAUNCH();
}

}  // namespace cuda
}  // namespace vasco
