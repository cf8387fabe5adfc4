// align_grids.h — the grids the alignment search reads (align.h): both maps
// at the matching cell, the moving map's walls as points, the reference's
// likelihood field and its max-pooled levels for branch and bound.
#ifndef VASCO_GPU_SRC_ALIGN_ALIGN_GRIDS_H
#define VASCO_GPU_SRC_ALIGN_ALIGN_GRIDS_H

#include <cstdint>
#include <vector>

#include "vasco_gpu/align.h"

namespace vasco {
namespace align_detail {

// A cell above this probability is a wall, below kFreeBelow known free (the
// band between is evidence too weak to reward or penalise).
constexpr float kWallAbove = 0.65f;
constexpr float kFreeBelow = 0.35f;

// A map at the matching cell: AlignMap's layout and meaning.
struct MatchGrid {
  int size_x = 0, size_y = 0;
  double resolution = 0;
  double origin_x = 0, origin_y = 0;
  std::vector<float> cells;
  float at(int x, int y) const { return cells[static_cast<size_t>(x) * size_y + y]; }
};

// `map` at cell `h`, with the same lower-left corner. A finer map is
// max-pooled (each input cell's centre falls in one output cell, which keeps
// the largest known probability: a thin wall stays a wall), a coarser or
// equal one sampled at each output cell's centre. Unknown stays unknown.
MatchGrid resample(const AlignMap &map, double h);

// The world positions of the centres of the wall cells of `grid`.
struct Points {
  std::vector<double> x, y;
  size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }
};
Points wall_points(const MatchGrid &grid);

// The reference's likelihood of a wall point at each cell: exp(-d^2 / 2)
// with d the distance in cells to the nearest wall cell, for d <= kReach;
// farther, -kFreePenalty on cells known free and 0 elsewhere (unknown, or
// neither wall nor free). `known` marks cells with any evidence.
constexpr int kReach = 2;
constexpr float kFreePenalty = 1.0f;
struct Field {
  int size_x = 0, size_y = 0;
  std::vector<float> value;
  std::vector<uint8_t> known;
};
Field likelihood_field(const MatchGrid &reference);

// Level d of the pyramid: at (x, y) the largest field value over cells
// [x, x + 2^d) x [y, y + 2^d), the field being 0 outside the map; stored for
// x in [-(2^d - 1), size_x), i.e. at index x + offset (likewise y), so that
// any window touching the map has its cell. Level 0 is the field itself.
struct PooledGrid {
  int offset = 0;
  int size_x = 0, size_y = 0;  // stored sizes
  std::vector<float> value;
};
std::vector<PooledGrid> pool_levels(const Field &field, int levels);

}  // namespace align_detail
}  // namespace vasco

#endif  // VASCO_GPU_SRC_ALIGN_ALIGN_GRIDS_H
