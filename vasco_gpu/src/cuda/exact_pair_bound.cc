#include "exact_pair_bound.h"

#include <algorithm>
#include <cstdlib>

#include "egrid_kernels.h"
#include "vasco_gpu/internal/parallel.h"

namespace vasco {
namespace cuda_host {
namespace {

// Tiles a beam's walk can enter, at most: the walk is monotone in x and y and
// moves at most one cell per step along each axis, so up to step k_max =
// table_size - 1 it stays in a box of that half-width, and it enters a new
// tile only by crossing a tile boundary. For a closed-form line the box is
// also bounded by the end cell. Degenerate lines (egrid_math.h) get the box
// bound alone, whatever their direction.
uint64_t tile_bound_of_beam(const oracle::ScanStart &s, const PlacedBeam &b, int table_size) {
  if (table_size <= 0) return 0;
  const int64_t reach = table_size - 1, tile = cuda::kTile;
  if (!egrid::is_closed_form_line(s.x1, s.y1, b.x2, b.y2)) return 2 * (static_cast<uint64_t>(reach) / tile + 1) + 1;
  auto tiles_crossed = [&](int64_t from, int64_t to) {
    const int64_t end = from + std::max(-reach, std::min(reach, to - from));
    auto floor_div = [&](int64_t v) { return v >= 0 ? v / tile : -((-v + tile - 1) / tile); };
    return static_cast<uint64_t>(std::llabs(floor_div(end) - floor_div(from)));
  };
  return 1 + tiles_crossed(s.x1, b.x2) + tiles_crossed(s.y1, b.y2);
}

}  // namespace

uint64_t exact_pair_bound(const PlacedBeam *beams, size_t n, const std::vector<oracle::ScanStart> &starts,
                          int table_size) {
  const int nt = n < (size_t(1) << 16) ? 1 : hardware_threads();
  std::vector<uint64_t> part(static_cast<size_t>(nt), 0);
  run_on_threads(nt, [&](int t) {
    const size_t a = n * t / nt, b = n * (t + 1) / nt;
    uint64_t sum = 0;
    for (size_t i = a; i < b; ++i) sum += tile_bound_of_beam(starts[beams[i].scan], beams[i], table_size);
    part[static_cast<size_t>(t)] = sum;
  });
  uint64_t total = 0;
  for (uint64_t p : part) total += p;
  return total;
}

uint64_t exact_beams_per_launch(int table_size) {
  const uint64_t per_beam = 2 * (static_cast<uint64_t>(std::max(table_size, 0)) / cuda::kTile + 2);
  return std::max<uint64_t>(1, (uint64_t(UINT32_MAX) - 1) / per_beam);
}

}  // namespace cuda_host
}  // namespace vasco
