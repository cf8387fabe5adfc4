// exact_tile_bound.h — how many kTile x kTile tiles one beam's walk can
// enter, at most: what sizes exact mode's (tile, beam) pair arrays before a
// launch, so that no apply waits for the real count. Written once for the
// host's sum (exact_pair_bound.cc) and the device placement's
// (exact_placement.cu).
#ifndef VASCO_GPU_SRC_CUDA_EXACT_TILE_BOUND_H
#define VASCO_GPU_SRC_CUDA_EXACT_TILE_BOUND_H

#include <cstdint>

#include "egrid_kernels.h"
#include "vasco_gpu/internal/egrid_math.h"

namespace vasco {
namespace cuda {

// Whatever the direction: the walk is monotone in x and y and moves at most
// one cell per step along each axis, so up to step table_size - 1 it stays
// in a box of that half-width, and it enters a new tile only by crossing a
// tile boundary.
VG_HD uint64_t max_beam_tile_bound(int table_size) {
  if (table_size <= 0) return 0;
  return 2 * (static_cast<uint64_t>(table_size - 1) / kTile + 1) + 1;
}

// Tile boundaries crossed from `from` towards `to`, the move clamped to
// `reach` cells (floor division: the tiles of negative cells count too).
VG_HD uint64_t tile_borders_crossed(int64_t from, int64_t to, int64_t reach) {
  int64_t move = to - from;
  move = move < -reach ? -reach : (move > reach ? reach : move);
  const int64_t end = from + move, tile = kTile;
  const int64_t a = from >= 0 ? from / tile : -((-from + tile - 1) / tile);
  const int64_t b = end >= 0 ? end / tile : -((-end + tile - 1) / tile);
  return static_cast<uint64_t>(b > a ? b - a : a - b);
}

// The beam from start cell (x1, y1) to end cell (x2, y2): for a closed-form
// line (egrid_math.h) the box is also bounded by the end cell; a degenerate
// line gets the box bound alone.
VG_HD uint64_t beam_tile_bound(int x1, int y1, int x2, int y2, int table_size) {
  if (table_size <= 0) return 0;
  if (!egrid::is_closed_form_line(x1, y1, x2, y2)) return max_beam_tile_bound(table_size);
  const int64_t reach = table_size - 1;
  return 1 + tile_borders_crossed(x1, x2, reach) + tile_borders_crossed(y1, y2, reach);
}

}  // namespace cuda
}  // namespace vasco

#endif  // VASCO_GPU_SRC_CUDA_EXACT_TILE_BOUND_H
