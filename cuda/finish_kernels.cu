// CARMEN's finish (DESIGN §2 step 7) on the device, so that a mapping
// session downloads only the finished map. One thread per ds x ds block sums
// its cells in double in CARMEN's order (i outer, j inner) and divides once,
// as finish_grid does on the host: the same float, bit for bit.
#include <algorithm>

#include "cuda_check.h"
#include "egrid_kernels.h"

namespace vasco {
namespace cuda {
namespace {

__device__ __forceinline__ float cell_prob(const GridCells &grid, size_t c) {
  return grid.sums ? prob_of_fixed(grid.logodds_prior, grid.sums[c]) : grid.probs[c];
}

__global__ void finish_blocks_kernel(GridCells grid, int size_y, int ds, int nx, int ny, float *blocks,
                                     int *bbox) {
  const size_t b = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (b >= static_cast<size_t>(nx) * ny) return;
  const int bx = static_cast<int>(b / ny), by = static_cast<int>(b % ny);
  double sum = 0;
  int count = 0;
  for (int i = bx * ds; i < (bx + 1) * ds; ++i) {
    for (int j = by * ds; j < (by + 1) * ds; ++j) {
      const float v = cell_prob(grid, static_cast<size_t>(i) * size_y + j);
      if (v != -1.0f) {
        sum += v;
        ++count;
      }
    }
  }
  float v = -1.0f;
  if (count > 0) {
    v = static_cast<float>(__ddiv_rn(sum, static_cast<double>(count)));
    atomicMin(&bbox[0], bx);
    atomicMax(&bbox[1], bx);
    atomicMin(&bbox[2], by);
    atomicMax(&bbox[3], by);
  }
  blocks[b] = v;
}

__global__ void crop_kernel(const float *blocks, int ny, int min_x, int min_y, int out_x, int out_y, float *out) {
  const size_t c = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (c >= static_cast<size_t>(out_x) * out_y) return;
  const int x = static_cast<int>(c / out_y), y = static_cast<int>(c % out_y);
  out[c] = blocks[static_cast<size_t>(x + min_x) * ny + (y + min_y)];
}

__global__ void window_kernel(GridCells grid, int size_y, int x0, int y0, int width, int height, float *out) {
  const size_t c = blockIdx.x * static_cast<size_t>(blockDim.x) + threadIdx.x;
  if (c >= static_cast<size_t>(width) * height) return;
  const int x = static_cast<int>(c / height), y = static_cast<int>(c % height);
  out[c] = cell_prob(grid, static_cast<size_t>(x0 + x) * size_y + (y0 + y));
}

unsigned blocks_of(size_t n) { return static_cast<unsigned>((n + 255) / 256); }

}  // namespace

void launch_finish_blocks(GridCells grid, int size_x, int size_y, int ds, float *blocks, int *bbox,
                          cudaStream_t stream) {
  const int nx = size_x / ds, ny = size_y / ds;
  const size_t n = static_cast<size_t>(nx) * ny;
  if (n == 0) return;
  finish_blocks_kernel<<<blocks_of(n), 256, 0, stream>>>(grid, size_y, ds, nx, ny, blocks, bbox);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_crop(const float *blocks, int ny, int min_x, int min_y, int out_x, int out_y, float *out,
                 cudaStream_t stream) {
  const size_t n = static_cast<size_t>(out_x) * out_y;
  if (n == 0) return;
  crop_kernel<<<blocks_of(n), 256, 0, stream>>>(blocks, ny, min_x, min_y, out_x, out_y, out);
  VG_CUDA_CHECK_LAUNCH();
}

void launch_read_window(GridCells grid, int size_y, int x0, int y0, int width, int height, float *out,
                        cudaStream_t stream) {
  const size_t n = static_cast<size_t>(width) * height;
  if (n == 0) return;
  window_kernel<<<blocks_of(n), 256, 0, stream>>>(grid, size_y, x0, y0, width, height, out);
  VG_CUDA_CHECK_LAUNCH();
}

}  // namespace cuda
}  // namespace vasco
