// launch_shape.cuh — the grid size of a launch of one thread per item, for
// the kernels' launchers (exact_*.cu).
#ifndef VASCO_CUDA_LAUNCH_SHAPE_CUH
#define VASCO_CUDA_LAUNCH_SHAPE_CUH

#include <cstddef>

namespace vasco {
namespace cuda {

// Blocks of `threads` threads that cover n items.
inline unsigned blocks_for(size_t n, unsigned threads) {
  return static_cast<unsigned>((n + threads - 1) / threads);
}

}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_CUDA_LAUNCH_SHAPE_CUH
