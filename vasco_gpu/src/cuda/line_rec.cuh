// line_rec.cuh — a beam's walk in the form a thread per cell needs: build
// it (make_line) and ask whether, and at which step, it visits a cell
// (step_of_cell), without division. Device code shared by the exact-mode
// kernels and the Bresenham check kernel.
#ifndef VASCO_CUDA_LINE_REC_CUH
#define VASCO_CUDA_LINE_REC_CUH

#include "egrid_kernels.h"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {

// Lines longer than this (in cells along either axis) are walked
// sequentially by each thread instead of tested in closed form; it keeps every
// product of the closed-form test below 2^31. Only degenerate beams (a range
// of -inf, or absurd resolutions) are this long.
constexpr int kClosedFormLimit = 1 << 14;

__device__ __forceinline__ LineRec make_line(int x1, int y1, int x2, int y2, float range, int table_size) {
  LineRec L;
  L.x1 = x1;
  L.y1 = y1;
  L.x2 = x2;
  L.y2 = y2;
  L.range = range;
  L.free_below = 0;
  L.flags = 0;
  const bool closed = egrid::is_closed_form_line(x1, y1, x2, y2);
  egrid::LineParams p{};
  if (closed) p = egrid::line_params(x1, y1, x2, y2);
  if (!closed || p.a >= kClosedFormLimit || p.b >= kClosedFormLimit) {
    L.flags = kDegenerate;
    L.sx1 = L.sy1 = L.two_a = L.two_b = L.bias = 0;
    L.k_max = table_size - 1;
    return L;
  }
  if (p.steep) L.flags |= kSteep;
  if (p.flipped) L.flags |= kFlipped;
  if (p.inc < 0) L.flags |= kBackward;
  L.sx1 = p.steep ? y1 : x1;
  L.sy1 = p.steep ? x1 : y1;
  if (p.flipped) L.sy1 = -L.sy1;
  L.two_a = p.a ? 2 * p.a : 1;
  L.two_b = 2 * p.b;
  L.bias = p.a ? p.a - (p.inc < 0 ? 1 : 0) : 0;
  L.k_max = min(p.a, table_size - 1);
  return L;
}

// The step at which line L visits (cx, cy), or -1.
__device__ __forceinline__ int step_of_cell(const LineRec &L, int cx, int cy) {
  if (L.flags & kDegenerate) {
    // Sequential walk, exactly the oracle's (rare: see kClosedFormLimit).
    int step = -1;
    egrid::walk_line(L.x1, L.y1, L.x2, L.y2, L.k_max + 1, [&](int x, int y, int k) {
      if (x == cx && y == cy) step = k;
      return step < 0;
    });
    return step;
  }
  const bool steep = L.flags & kSteep, backward = L.flags & kBackward;
  const int maj = steep ? cy : cx;
  int mn = steep ? cx : cy;
  if (L.flags & kFlipped) mn = -mn;
  const int k = backward ? L.sx1 - maj : maj - L.sx1;
  if (k < 0 || k > L.k_max) return -1;
  const int m = backward ? L.sy1 - mn : mn - L.sy1;
  if (m < 0 || 2 * m > L.two_b) return -1;
  // m is the walk's minor offset after k steps iff
  // two_a*m <= two_b*k + bias < two_a*(m+1)  (egrid_math.h line_step_of_cell)
  const int num = L.two_b * k + L.bias;
  const int lo = L.two_a * m;
  return (num >= lo && num < lo + L.two_a) ? k : -1;
}

}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_CUDA_LINE_REC_CUH
