#include "exact_pair_bound.h"

#include <algorithm>
#include <cstdlib>

#include "egrid_kernels.h"
#include "exact_tile_bound.h"
#include "vasco_gpu/internal/parallel.h"

namespace vasco {
namespace cuda_host {

uint64_t exact_pair_bound(const PlacedBeam *beams, size_t n, const std::vector<oracle::ScanStart> &starts,
                          int table_size) {
  const int nt = n < (size_t(1) << 16) ? 1 : hardware_threads();
  std::vector<uint64_t> part(static_cast<size_t>(nt), 0);
  run_on_threads(nt, [&](int t) {
    const size_t a = n * t / nt, b = n * (t + 1) / nt;
    uint64_t sum = 0;
    for (size_t i = a; i < b; ++i) {
      const oracle::ScanStart &s = starts[beams[i].scan];
      sum += cuda::beam_tile_bound(s.x1, s.y1, beams[i].x2, beams[i].y2, table_size);
    }
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
