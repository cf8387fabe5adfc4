// The host side of the GPU global search (align_gpu.h): the rotations' cos
// and sin as the CPU search computes them, the device's local maxima, and
// best_distinct (align_search.h) among them.
#include "align_gpu.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "vasco_gpu/error.h"
#include "vasco_gpu/internal/se2.h"

namespace vasco {
namespace align_detail {

#if defined(VASCO_HAVE_CUDA)
namespace {

// After the list overflows at the floor: floors at these fractions of the
// best sum. The candidates that matter score near the best.
constexpr float kRetryFractions[] = {0.25f, 0.5f, 0.75f, 0.9f};

}  // namespace
#endif

bool gpu_search_compiled() {
#if defined(VASCO_HAVE_CUDA)
  return true;
#else
  return false;
#endif
}

std::vector<Leaf> gpu_search(const SearchSpace &space, float floor_sum, int keep, const Distinctness &distinct,
                             int threads, int device) {
#if !defined(VASCO_HAVE_CUDA)
  (void)space, (void)floor_sum, (void)keep, (void)distinct, (void)threads, (void)device;
  throw Error(ErrorCode::NoGpu, "align_maps: the GPU search is not compiled in (a build without CUDA)");
#else
  if (space.rotations <= 0 || space.points == nullptr || space.points->size() == 0) return {};
  const PooledGrid &field = space.levels->front();
  const size_t r = static_cast<size_t>(space.rotations);
  std::vector<double> cos_k(r), sin_k(r);
  for (size_t k = 0; k < r; ++k) {  // rotated_cells' std::cos and std::sin
    cos_k[k] = std::cos(space.theta(static_cast<int>(k)));
    sin_k[k] = std::sin(space.theta(static_cast<int>(k)));
  }
  GpuLeafQuery q;
  q.px = space.points->x.data();
  q.py = space.points->y.data();
  q.n = static_cast<int>(space.points->size());
  q.c_x = space.c_x;
  q.c_y = space.c_y;
  q.h = space.h;
  q.cos_k = cos_k.data();
  q.sin_k = sin_k.data();
  q.box = space.box.data();
  q.rotations = space.rotations;
  q.field = field.value.data();
  q.size_x = field.size_x;
  q.size_y = field.size_y;
  q.device = device;
  GpuLeafSearch leaves(q);
  std::vector<Leaf> maxima;
  float best = 0;
  if (leaves.maxima(floor_sum, &maxima, &best)) return best_distinct(std::move(maxima), space, keep, distinct);
  for (const float fraction : kRetryFractions) {
    const float floor = std::max(floor_sum, fraction * best);
    if (leaves.maxima(floor, &maxima, &best)) return best_distinct(std::move(maxima), space, keep, distinct);
  }
  return branch_and_bound(space, floor_sum, keep, distinct, threads);
#endif
}

}  // namespace align_detail
}  // namespace vasco
